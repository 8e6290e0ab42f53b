"""Parse one source line into a statement tree with column spans.

The grammar is ``grammar.lark`` (LALR, contextual lexer); a Transformer runs during
parsing and builds the small node classes below directly, so no Lark tree is kept.
Columns count from 1; ``end`` is the column just after the node (Lark's ``end_column``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from pathlib import Path
from typing import Union

from lark import Lark, Token, Transformer
from lark.exceptions import UnexpectedCharacters, UnexpectedToken

#: Longest exponent and digit count accepted in a literal: bounds the work exact
#: arithmetic can be asked to do (1e4000 is already far beyond float16).
MAX_EXPONENT = 4000
MAX_DIGITS = 1000
#: Largest numerator and denominator exact arithmetic may hold, in bits: a little above
#: the literals' own range (10^4000 is 13,288 bits), far beyond float16 (17 bits) and a
#: 32-bit word, and small enough that every operation and printing stays quick.
MAX_BITS = 13_300
#: Deepest expression tree accepted (operators nested in operators, e.g. a 201-term sum
#: or 201 unary minus signs): evaluation recurses once per level.
MAX_DEPTH = 200
#: Longest piece of source quoted in a message.
QUOTE_LIMIT = 40


@dataclass(frozen=True, slots=True)
class Num:
    """A numeric literal (or a folded constant expression, kind dec). ``kind`` is dec,
    hex, bin or raw (raw: ``value`` is the bits); ``error`` is set when it is malformed."""

    value: int | Fraction
    kind: str
    col: int
    end: int
    error: str = ""
    negative_zero: bool = False  # a folded constant expression that came out as -0


@dataclass(frozen=True, slots=True)
class Ref:
    """A name: a property in a property position, otherwise a constant or .rept variable."""

    name: str
    col: int
    end: int


@dataclass(frozen=True, slots=True)
class Neg:
    operand: "Expr"
    col: int
    end: int
    depth: int = 1  # levels of operators in this tree (bounded by MAX_DEPTH)


@dataclass(frozen=True, slots=True)
class BinOp:
    op: str
    left: "Expr"
    right: "Expr"
    col: int
    end: int
    depth: int = 1


@dataclass(frozen=True, slots=True)
class Str:
    """A string operand (only ``.include`` takes one)."""

    text: str
    col: int
    end: int


Expr = Union[Num, Ref, Neg, BinOp]
Operand = Union[Num, Ref, Neg, BinOp, Str]


@dataclass(frozen=True, slots=True)
class Instruction:
    mnemonic: str  # as written
    col: int
    end: int
    operands: tuple[Operand, ...]


@dataclass(frozen=True, slots=True)
class Assignment:
    name: str
    col: int
    end: int
    expr: Expr


@dataclass(frozen=True, slots=True)
class Directive:
    name: str  # with its dot, as written
    col: int
    end: int
    args: tuple[Operand, ...]


Statement = Union[Instruction, Assignment, Directive]


class SyntaxProblem(Exception):
    """A line that does not parse: message and the span to underline."""

    def __init__(self, message: str, col: int, end: int) -> None:
        super().__init__(message)
        self.message = message
        self.col = col
        self.end = end


def quote(text: str) -> str:
    """``text`` for a message: cut to :data:`QUOTE_LIMIT` characters with ``...``."""
    return text if len(text) <= QUOTE_LIMIT else text[: QUOTE_LIMIT - 3] + "..."


def depth(node: object) -> int:
    """Levels of operators in an expression tree (0 for a literal or a name)."""
    return node.depth if type(node) in (Neg, BinOp) else 0


_DEC = re.compile(r"(?:\d+(?:_\d+)*)?(?:\.(?:\d+(?:_\d+)*)?)?(?:[eE][+-]?\d+(?:_\d+)*)?")
_DIGITS = {"HEX": ("0123456789abcdefABCDEF", 16), "BIN": ("01", 2), "RAW": ("0123456789abcdefABCDEF", 16)}
_KIND = {"NUMBER": "dec", "HEX": "hex", "BIN": "bin", "RAW": "raw"}


def parse_number(text: str, token_type: str) -> tuple[int | Fraction, str]:
    """The exact value of a literal token and an error message ('' when well formed).

    Decimal literals give an int when integral, else a Fraction; 0x and 0b give ints;
    0h gives the raw 16 bits. ``_`` may separate digits (not lead, trail or double).
    """
    if token_type == "NUMBER":
        if text.isdigit() and text.isascii() and len(text) <= MAX_DIGITS:
            return int(text), ""
        if not _DEC.fullmatch(text) or not any(c.isdigit() for c in text.split("e")[0].split("E")[0]):
            return 0, f"malformed number '{quote(text)}'"
        mantissa, _, exponent = text.replace("_", "").lower().partition("e")
        magnitude = exponent.lstrip("+-").lstrip("0") or "0"
        if len(magnitude) > 5 or int(magnitude) > MAX_EXPONENT:
            return 0, f"exponent of '{quote(text)}' is out of range (at most {MAX_EXPONENT} in magnitude)"
        if len(mantissa) > MAX_DIGITS:
            return 0, f"number '{text[:20]}...' has too many digits (at most {MAX_DIGITS})"
        sign = "-" if exponent.startswith("-") else ""
        value = Fraction(mantissa + ("e" + sign + magnitude if exponent else ""))
        if max(value.numerator.bit_length(), value.denominator.bit_length()) > MAX_BITS:
            return 0, f"number '{quote(text)}' is out of range (exact values are limited to {MAX_BITS:,} bits)"
        return (value.numerator if value.denominator == 1 else value), ""
    digits, base = _DIGITS[token_type]
    body = text[2:]
    name = {"HEX": "hexadecimal", "BIN": "binary", "RAW": "raw-bits"}[token_type]
    if not body or body.startswith("_") or body.endswith("_") or "__" in body or any(
        c not in digits and c != "_" for c in body
    ):
        return 0, f"malformed {name} number '{quote(text)}'"
    body = body.replace("_", "")
    if len(body) > MAX_DIGITS:
        return 0, f"number '{text[:20]}...' has too many digits (at most {MAX_DIGITS})"
    if token_type == "RAW" and len(body) > 4:
        return 0, f"raw bits '{quote(text)}' have more than 4 hex digits (16 bits)"
    return int(body, base), ""


class _Builder(Transformer):
    """Turns parse-tree callbacks into the node classes above (runs inside the parser)."""

    def start(self, children: list) -> Statement | None:
        return children[0] if children else None

    def operand(self, children: list) -> Expr:
        return children[0]

    def instruction(self, children: list) -> Instruction:
        name = children[0]
        return Instruction(str(name), name.column, name.end_column, tuple(children[1:]))

    def assignment(self, children: list) -> Assignment:
        name, _, expr = children
        return Assignment(str(name), name.column, name.end_column, expr)

    def directive(self, children: list) -> Directive:
        name = children[0]
        args = tuple(
            Str(str(c)[1:-1], c.column, c.end_column) if isinstance(c, Token) else c for c in children[1:]
        )
        return Directive(str(name), name.column, name.end_column, args)

    def number(self, children: list) -> Num:
        (tok,) = children
        value, error = parse_number(str(tok), tok.type)
        return Num(value, _KIND[tok.type], tok.column, tok.end_column, error)

    def ref(self, children: list) -> Ref:
        (tok,) = children
        return Ref(str(tok), tok.column, tok.end_column)

    def neg(self, children: list) -> Neg:
        sign, operand = children
        return Neg(operand, sign.column, operand.end, _deeper(operand, sign.column, operand.end))

    def pos(self, children: list) -> Expr:
        sign, operand = children
        return _respan(operand, sign.column, operand.end)

    def paren(self, children: list) -> Expr:
        left, inner, right = children
        return _respan(inner, left.column, right.end_column)

    def binop(self, children: list) -> BinOp:
        left, op, right = children
        level = _deeper(left if depth(left) >= depth(right) else right, left.col, right.end)
        return BinOp(str(op), left, right, left.col, right.end, level)


def _deeper(child: Expr, col: int, end: int) -> int:
    """The depth of an operator over ``child``; beyond MAX_DEPTH a SyntaxProblem."""
    level = depth(child) + 1
    if level > MAX_DEPTH:
        raise SyntaxProblem(f"expression nested too deeply (more than {MAX_DEPTH} levels of operators)", col, end)
    return level


def _respan(node: Expr, col: int, end: int) -> Expr:
    """The same expression, underlined over its parentheses or leading '+'."""
    cls = type(node)
    fields = {f: getattr(node, f) for f in cls.__dataclass_fields__}
    fields.update(col=col, end=end)
    return cls(**fields)


@lru_cache(maxsize=1)
def _parser() -> Lark:
    grammar = (Path(__file__).with_name("grammar.lark")).read_text(encoding="utf-8")
    return Lark(grammar, parser="lalr", lexer="contextual", transformer=_Builder(), maybe_placeholders=False,
                start=["start", "operand"])


_TOKEN_WORDS = {
    "NAME": "a name",
    "NUMBER": "a number",
    "HEX": "a number",
    "BIN": "a number",
    "RAW": "raw bits",
    "DIRECTIVE": "a directive",
    "STRING": "a string",
    "COMMA": "','",
    "EQUALS": "'='",
    "PLUS": "'+'",
    "MINUS": "'-'",
    "STAR": "'*'",
    "SLASH": "'/'",
    "LPAR": "'('",
    "RPAR": "')'",
    "$END": "end of line",
}


def _expected(names: set[str]) -> str:
    words = sorted({_TOKEN_WORDS.get(n, n) for n in names})
    if len(words) > 1:
        return ", ".join(words[:-1]) + " or " + words[-1]
    return words[0] if words else "nothing"


def parse_line(text: str) -> Statement | None:
    """Parse one line (no newline). None for a blank or comment-only line.

    Raises SyntaxProblem with a column span for anything the grammar rejects.
    """
    try:
        return _parser().parse(text, start="start")
    except UnexpectedCharacters as exc:
        ch = text[exc.pos_in_stream] if exc.pos_in_stream < len(text) else ""
        shown = repr(ch) if ch.isprintable() else f"U+{ord(ch):04X}"
        raise SyntaxProblem(f"unexpected character {shown}", exc.column, exc.column + 1) from None
    except UnexpectedToken as exc:
        tok = exc.token
        names = set(exc.expected)
        if text[: tok.column or 0].count("(") <= text[: tok.column or 0].count(")"):
            names.discard("RPAR")  # LALR's expected set lists ')' even with no '(' open
        expected = _expected(names)
        if tok.type == "$END":
            col = len(text.split(";")[0].split("//")[0].rstrip()) + 1
            raise SyntaxProblem(f"unexpected end of line, expected {expected}", col, col + 1) from None
        what = f"'{quote(str(tok))}'"
        raise SyntaxProblem(f"unexpected {what}, expected {expected}", tok.column, tok.end_column) from None


_WS = "[ \t\f\v\r]"
# mnemonic, whitespace, operand text (no string, no comment; trailing whitespace is
# stripped afterwards), optional comment. The operand group is greedy and ends where a
# comment can start, so a failed match backtracks once over the line, not once per
# character (a lazy group followed by whitespace was quadratic in the line length).
_INSTRUCTION = re.compile(rf"{_WS}*([A-Za-z_][A-Za-z0-9_]*){_WS}+((?:[^;/\"]|/(?!/))*)(?:(?://|;).*)?", re.ASCII)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*", re.ASCII)
#: operand text -> its tree with columns counted from the operand's first character
_OPERANDS: dict[str, Expr | None] = {}
_OPERAND_CACHE_LIMIT = 1 << 16


def clear_operand_cache() -> None:
    """Forget parsed operands (benchmarks measure a cold cache)."""
    _OPERANDS.clear()


def parse_instruction(text: str) -> Instruction | None:
    """Parse an instruction line operand by operand, or None when the line is anything
    else or does not parse (then :func:`parse_line` gives the verdict and its message).

    Each operand is parsed with the grammar's ``operand`` start symbol and cached by its
    text, so the repeated expressions of real programs are parsed once. The result is the
    tree :func:`parse_line` builds for the same line.
    """
    m = _INSTRUCTION.fullmatch(text)
    if m is None or not m.group(2).strip(" \t\f\v\r"):
        return None
    operands = []
    pos = m.start(2)
    for piece in m.group(2).split(","):
        stripped = piece.strip(" \t\f\v\r")
        if not stripped:
            return None
        col = pos + len(piece) - len(piece.lstrip(" \t\f\v\r")) + 1
        pos += len(piece) + 1
        if _NAME.fullmatch(stripped):
            operands.append(Ref(stripped, col, col + len(stripped)))
            continue
        node = _OPERANDS.get(stripped, False)
        if node is False:
            try:
                node = _parser().parse(stripped, start="operand")
            except (UnexpectedCharacters, UnexpectedToken, SyntaxProblem):
                node = None
            if len(_OPERANDS) >= _OPERAND_CACHE_LIMIT:
                _OPERANDS.clear()
            _OPERANDS[stripped] = node
        if node is None:
            return None
        operands.append(_shift(node, col - 1))
    name = m.group(1)
    col = m.start(1) + 1
    return Instruction(name, col, col + len(name), tuple(operands))


def _shift(node: Expr, delta: int) -> Expr:
    """The same tree, ``delta`` columns to the right."""
    cls = type(node)
    if cls is Num:
        return Num(node.value, node.kind, node.col + delta, node.end + delta, node.error, node.negative_zero)
    if cls is Ref:
        return Ref(node.name, node.col + delta, node.end + delta)
    if cls is Neg:
        return Neg(_shift(node.operand, delta), node.col + delta, node.end + delta, node.depth)
    return BinOp(node.op, _shift(node.left, delta), _shift(node.right, delta), node.col + delta, node.end + delta,
                 node.depth)
