"""The assembler: source text to a :class:`Program`, with every diagnostic of the run.

Lines are read one at a time: the fast path (:mod:`.fastpath`) encodes plain
instruction lines, everything else goes through the Lark grammar (:mod:`.parser`), and
instructions are encoded by :mod:`.operands`. Statements run as soon as they are read,
except inside a ``.rept`` block, whose body is collected and then run once per iteration;
a body's table instructions are compiled once (:mod:`.compiled`) and fall back to the
general path on any iteration that could need a diagnostic.
ISA extensions (``ts`` of the hybrid extension, :mod:`rend3r.isa.extensions`) are accepted
only once enabled, by ``isa_ext=`` or a ``.isa_ext`` directive.
"""

from __future__ import annotations

import difflib
import os
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Iterable, Mapping

from ..errors import Rend3rError
from ..fileio import read_limited
from ..isa.extensions import EXTENSIONS
from ..isa.tables import F_MNEMONICS, MNEMONIC_TABLE
from ..isa.targets import TARGETS, Target
from .diagnostics import ERROR, WARNING, Diagnostic, format_all
from .compiled import Words, compile_instruction, plain_number
from .expressions import POISON, EvalError, Value, describe, evaluate, fold
from .fastpath import fast_line
from .operands import PAIRS, OperandEncoder
from .parser import (
    Assignment,
    BinOp,
    Directive,
    Instruction,
    Neg,
    Operand,
    Ref,
    Statement,
    Str,
    SyntaxProblem,
    parse_instruction,
    parse_line,
    quote,
)
from .program import Emitted, Program, SourceLoc

# Limits on what one run may be asked to do (docs/assembly.md, "Limits"): each bounds
# time or memory, and reaching one is an error naming it, never a hang or a crash.
#: Statements run after .rept expansion. A statement the fast path does not take counts
#: one more per operand and operator, and a line an .include reads counts as one: the
#: count bounds the time as well as the words.
MAX_STATEMENTS = 1 << 20
#: Bytes of one source file (the main file or an included one).
MAX_SOURCE = 32 << 20
#: Lines and bytes read in one run, counting every file each time it is (re)read.
MAX_LINES = 1 << 22
MAX_READ = 64 << 20
#: Characters the full grammar may parse in one run (lines the fast path does not take,
#: each time they are read): Lark takes up to ~50 us a character on a loaded machine.
MAX_PARSED = 256 << 10
#: Characters of one line (C's translation limit is 4,095): keeps the worst line (a
#: few thousand tokens for the full parser) well under a second.
MAX_LINE = 4_096
#: Nesting of .include and of .rept blocks (each level is a level of recursion).
MAX_INCLUDE_DEPTH = 32
MAX_REPT_DEPTH = 64
#: Errors after which the CLI stops (``--max-errors``; 0 = no limit).
MAX_ERRORS = 20
WORD_LIMIT = 1 << 32

MNEMONICS = (*F_MNEMONICS, *MNEMONIC_TABLE)
DIRECTIVES = (".include", ".rept", ".endr", ".word", ".isa_ext")
#: ISA extensions a program may opt into (docs/isa-extensions.md) -> the mnemonics each adds
ISA_EXTENSIONS: Mapping[str, tuple[str, ...]] = EXTENSIONS
#: what ``isa_ext=`` accepts: one extension name, several, or None
IsaExt = str | Iterable[str] | None


@dataclass
class AssemblyResult:
    """What one assembler run produced."""

    program: Program
    diagnostics: list[Diagnostic] = field(default_factory=list)
    mnemonics_used: set[str] = field(default_factory=set)
    stopped_at: int = 0  # the max_errors limit the run stopped at (0: it ran to its end)
    #: the files the run read or looked for, resolved, in reading order: the source and each
    #: .include (one not found: the path beside the including file), for a watcher to follow
    files: list[Path] = field(default_factory=list)

    @property
    def mode(self) -> str:
        """The frame mode the program calls for (as ``rend3r emulate`` runs it): hybrid
        when it uses ``ts``, raster when it uses ``tr``, else raytrace."""
        used = self.mnemonics_used
        return "hybrid" if "ts" in used else "raster" if "tr" in used else "raytrace"

    @property
    def ok(self) -> bool:
        """True when there are no errors (warnings allowed)."""
        return not any(d.is_error for d in self.diagnostics)

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.is_error]

    @property
    def warnings(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if not d.is_error]

    def format_diagnostics(self) -> str:
        """Every diagnostic with its source line and caret, then a summary line (and a
        line saying the run stopped, when it reached its error limit)."""
        text = format_all(self.diagnostics)
        if self.stopped_at:
            text += f"\nstopped after {self.stopped_at} errors (the limit; --max-errors 0 for none)"
        return text


def resolve_isa_ext(isa_ext: IsaExt) -> frozenset[str]:
    """The set of ISA extension names ``isa_ext`` enables (one name, or several)."""
    names = {isa_ext} if isinstance(isa_ext, str) else set(isa_ext or ())
    unknown = sorted(n for n in names if n.lower() not in ISA_EXTENSIONS)
    if unknown:
        raise Rend3rError(f"unknown ISA extension '{unknown[0]}' (known: {', '.join(sorted(ISA_EXTENSIONS))})")
    return frozenset(n.lower() for n in names)


class _Abort(Exception):
    """Stop assembling (a limit was reached; its error is reported already)."""


@dataclass
class _Stmt:
    stmt: Statement
    file: str
    line: int
    text: str
    cost: int = 1  # what it counts against MAX_STATEMENTS (see _cost)
    words: Words | None = None  # compiled (a .rept body's instruction): see compiled.py
    loc: SourceLoc | None = None  # where its words come from, made once for every iteration


@dataclass
class _Fixed:
    """A fast-path line: its words are known without evaluation."""

    mnemonic: str
    words: tuple[int, ...]
    loc: SourceLoc
    text: str


@dataclass
class _Rept:
    stmt: Directive
    file: str
    line: int
    text: str
    body: list = field(default_factory=list)


def _cost(stmt: Statement) -> int:
    """What a parsed statement counts against MAX_STATEMENTS: one, plus one per node of
    its operands' trees (names, literals and operators; counted without recursion), so
    the count follows the time it takes to run."""
    todo = list(stmt.operands if isinstance(stmt, Instruction) else
                (stmt.expr,) if isinstance(stmt, Assignment) else stmt.args)
    count = 1
    while todo:
        node = todo.pop()
        count += 1
        if isinstance(node, Neg):
            todo.append(node.operand)
        elif isinstance(node, BinOp):
            todo += (node.left, node.right)
    return count


def _folded(stmt: Statement) -> Statement:
    """The statement with its constant arithmetic done (see :func:`.expressions.fold`)."""
    if isinstance(stmt, Instruction):
        return Instruction(stmt.mnemonic, stmt.col, stmt.end, tuple(fold(o) for o in stmt.operands))
    if isinstance(stmt, Assignment):
        return Assignment(stmt.name, stmt.col, stmt.end, fold(stmt.expr))
    return Directive(stmt.name, stmt.col, stmt.end, tuple(fold(a) for a in stmt.args))


def resolve_target(target: str | Target | None) -> Target | None:
    """A Target from its name (see :data:`rend3r.isa.targets.TARGETS`)."""
    if target is None or isinstance(target, Target):
        return target
    try:
        return TARGETS[target]
    except KeyError:
        raise Rend3rError(f"unknown target '{target}' (known: {', '.join(sorted(TARGETS))})") from None


class Assembler:
    """One assembler run; use :func:`assemble_source` or :func:`assemble_file`."""

    def __init__(self, include_paths: Iterable[str | os.PathLike[str]] = (), target: str | Target | None = None,
                 fast: bool = True, isa_ext: IsaExt = (), max_errors: int = 0, werror: bool = False) -> None:
        self.include_paths = [Path(p) for p in include_paths]
        self.target = resolve_target(target)
        self.limits = (
            {"lt": self.target.lights, "sp": self.target.shapes, "tr": self.target.triangles} if self.target else None
        )
        self.fast = fast
        self.entries: list[Emitted] = []
        self.address = 0
        self.diagnostics: list[Diagnostic] = []
        self._seen: set[tuple] = set()
        self.mnemonics: set[str] = set()
        self.env: dict[str, Value] = {}
        self.plain: dict[str, int | Fraction] = {}  # the env's plain numbers (compiled.plain_number)
        self.defined_at: dict[str, str] = {}
        self.scopes: list[list[str]] = []  # constants defined in each running .rept iteration
        self.include_stack: list[Path] = []
        # (including file, name) -> path, resolved path, text (None: not found or not read)
        self.includes: dict[tuple[str, str], tuple[Path, Path, str] | None] = {}
        self.include_depth = 0
        self.files: dict[Path, None] = {}  # AssemblyResult.files, in order
        self.statements = 0
        self.lines_read = 0
        self.parsed = 0  # characters sent to the full grammar
        self.bytes_read = 0
        self.rept_depth = 0  # .rept blocks running
        self.max_errors = max_errors
        self.errors_counted = {ERROR, WARNING} if werror else {ERROR}  # what max_errors counts
        self.error_count = 0
        self.stopped_at = 0
        # where the statement being run comes from: file, line, text, context
        self.where: tuple[str, int, str, tuple[str, ...]] = ("", 0, "", ())
        self.mnemonic_names: tuple[str, ...] = MNEMONICS  # the base ones and those of enabled extensions
        self.hybrid = False  # the hybrid extension is enabled (ts; sp/tr checked against the selection)
        self.operands = OperandEncoder(self)
        for name in resolve_isa_ext(isa_ext):
            self.enable(name)

    def enable(self, extension: str) -> None:
        """Accept the mnemonics of ISA extension ``extension`` (a key of ISA_EXTENSIONS)."""
        new = tuple(m for m in ISA_EXTENSIONS[extension] if m not in self.mnemonic_names)
        self.mnemonic_names += new
        if extension == "hybrid":
            self.hybrid = True

    # -- diagnostics -------------------------------------------------------------------

    def report(self, severity: str, message: str, col: int = 1, end: int = 0) -> None:
        file, line, text, context = self.where
        key = (severity, message, file, line, col)
        if key in self._seen:
            return  # the same problem on every .rept iteration is reported once
        self._seen.add(key)
        self.diagnostics.append(Diagnostic(severity, message, file, line, col, end, text, context))
        if severity in self.errors_counted:
            self.error_count += 1
            if self.error_count == self.max_errors:
                self.stopped_at = self.max_errors
                raise _Abort

    def error(self, message: str, col: int = 1, end: int = 0) -> None:
        self.report(ERROR, message, col, end)

    def warning(self, message: str, col: int = 1, end: int = 0) -> None:
        self.report(WARNING, message, col, end)

    # -- reading -----------------------------------------------------------------------

    def count_read(self, text: str, cost: int) -> None:
        """Charge the reading of ``text`` to the run's budgets (``cost`` statements
        besides): beyond a limit, an error here and the run stops."""
        self.lines_read += text.count("\n") + 1
        self.bytes_read += len(text)
        if self.lines_read > MAX_LINES or self.bytes_read > MAX_READ:
            self.error(f"sources too large: more than {MAX_LINES:,} lines or {MAX_READ:,} bytes read in all "
                       "(an .include in a .rept reads its file again each time)")
            raise _Abort
        self.count_statement(cost)

    def run_text(self, text: str, file: str, context: tuple[str, ...] = ()) -> None:
        """Read and run ``text`` as the lines of ``file``."""
        open_repts: list[_Rept] = []
        body: list | None = None  # where statements go while a .rept is open
        fast = self.fast
        limits = self.limits
        entries = self.entries
        if "\r" in text:
            text = text.replace("\r\n", "\n")
        for lineno, line in enumerate(text.split("\n"), 1):
            if len(line) > MAX_LINE:
                self.where = (file, lineno, line, context)
                self.error(f"line is {len(line):,} characters long; the limit is {MAX_LINE:,}", MAX_LINE + 1)
                continue
            hit = fast_line(line, limits) if fast else None
            if hit is not None:
                if not hit:
                    continue
                mnemonic, words, col = hit
                loc = SourceLoc(file, lineno, col)
                if body is None:
                    self.statements += 1
                    if self.statements > MAX_STATEMENTS:
                        self.where = (file, lineno, line, context)
                        self.too_large()
                    entries.append(Emitted(self.address, words, loc, line))
                    self.address += len(words)
                    if mnemonic:  # "" for .word
                        self.mnemonics.add(mnemonic)
                    if self.hybrid and mnemonic in PAIRS:
                        self.check_selection(mnemonic, loc, line, context)
                else:
                    body.append(_Fixed(mnemonic, words, loc, line))
                continue
            self.where = (file, lineno, line, context)
            self.parsed += len(line)
            if self.parsed > MAX_PARSED:
                self.error(f"sources too complex: more than {MAX_PARSED:,} characters of lines that need the full "
                           "parser (expressions, directives, errors)")
                raise _Abort
            stmt = parse_instruction(line) if fast else None
            if stmt is None:
                try:
                    stmt = parse_line(line)
                except SyntaxProblem as p:
                    self.error(p.message, p.col, p.end)
                    continue
            if stmt is None:
                continue
            kind = stmt.name.lower() if isinstance(stmt, Directive) else ""
            if kind == ".rept":
                if len(open_repts) + self.rept_depth >= MAX_REPT_DEPTH:
                    self.error(f".rept blocks nested too deeply (more than {MAX_REPT_DEPTH} levels)", stmt.col, stmt.end)
                    raise _Abort
                node = _Rept(stmt, file, lineno, line)
                if body is not None:
                    body.append(node)
                open_repts.append(node)
                body = node.body
            elif kind == ".endr":
                if stmt.args:
                    self.error(".endr takes no operands", stmt.args[0].col, stmt.args[-1].end)
                if not open_repts:
                    self.error(".endr without a .rept", stmt.col, stmt.end)
                    continue
                done = open_repts.pop()
                if open_repts:
                    body = open_repts[-1].body
                else:
                    body = None
                    self.run_rept(done, context)
            elif body is not None:
                folded = _folded(stmt)
                words = compile_instruction(folded, limits) if fast else None
                body.append(_Stmt(folded, file, lineno, line, _cost(stmt), words, SourceLoc(file, lineno, stmt.col)))
            else:
                self.run_statement(_Stmt(stmt, file, lineno, line, _cost(stmt)), context)
        for node in open_repts:
            self.where = (node.file, node.line, node.text, context)
            self.error(".rept without a matching .endr", node.stmt.col, node.stmt.end)

    def count_statement(self, cost: int = 1) -> None:
        self.statements += cost
        if self.statements > MAX_STATEMENTS:
            self.too_large()

    def too_large(self) -> None:
        file, line, _, _ = self.where
        self.where = (file, line, "", ())
        self.error(f"program too large: more than {MAX_STATEMENTS:,} statements after .rept expansion "
                   "(each operand, operator and line read by .include counts as one)")
        raise _Abort

    # -- running -----------------------------------------------------------------------

    def run_item(self, item: _Fixed | _Stmt | _Rept, context: tuple[str, ...]) -> None:
        if isinstance(item, _Fixed):
            self.count_statement()
            self.emit_instruction(item.mnemonic, item.words, item.loc, item.text, context)
        elif isinstance(item, _Rept):
            self.run_rept(item, context)
        else:
            self.run_statement(item, context)

    def emit(self, mnemonic: str, words: tuple[int, ...], loc: SourceLoc, text: str) -> None:
        self.entries.append(Emitted(self.address, words, loc, text))
        self.address += len(words)
        if mnemonic:
            self.mnemonics.add(mnemonic)

    def emit_instruction(self, mnemonic: str, words: tuple[int, ...], loc: SourceLoc, text: str,
                         context: tuple[str, ...]) -> None:
        """Emit an instruction's words, checking an sp/tr pair against the ``ts`` selection."""
        self.emit(mnemonic, words, loc, text)
        if self.hybrid and mnemonic in PAIRS:
            self.check_selection(mnemonic, loc, text, context)

    def check_selection(self, mnemonic: str, loc: SourceLoc, text: str, context: tuple[str, ...]) -> None:
        """Warn, at the mnemonic, when an sp/tr pair writes another table than its own
        (see :meth:`.OperandEncoder.selection_warning`)."""
        message = self.operands.selection_warning(mnemonic)
        if message is not None:
            self.where = (loc.file, loc.line, text, context)
            self.warning(message, loc.col, loc.col + len(mnemonic))

    def run_rept(self, node: _Rept, context: tuple[str, ...]) -> None:
        self.where = (node.file, node.line, node.text, context)
        self.count_statement()
        args = node.stmt.args
        if not 1 <= len(args) <= 2:
            self.error(".rept takes COUNT[, VAR]", node.stmt.col, node.stmt.end)
            return
        count = self.integer(args[0], "the .rept count", 0, MAX_STATEMENTS)
        var = self.new_name(args[1], "a .rept variable") if len(args) == 2 else None
        if count is None or (len(args) == 2 and var is None):
            return
        self.rept_depth += 1
        where = f"{node.file}:{node.line}"
        try:
            for i in range(count):
                label = f"{var}={i}" if var else f"#{i}"
                inner = (f"in .rept iteration {label} ({where})", *context)
                self.scopes.append([])
                if var:
                    self.define(var, Value(i), where)
                for item in node.body:
                    self.run_item(item, inner)
                for name in self.scopes.pop():
                    del self.env[name]
                    del self.defined_at[name]
                    self.plain.pop(name, None)
        finally:
            self.rept_depth -= 1

    def run_statement(self, item: _Stmt, context: tuple[str, ...]) -> None:
        self.where = (item.file, item.line, item.text, context)
        self.count_statement(item.cost)
        stmt = item.stmt
        words = item.words(self.plain) if item.words is not None else None
        if words is not None:
            self.emit_instruction(stmt.mnemonic.lower(), words, item.loc, item.text, context)
        elif isinstance(stmt, Instruction):
            words = self.operands.instruction(stmt)
            if words is not None:
                loc = SourceLoc(item.file, item.line, stmt.col)
                self.emit_instruction(stmt.mnemonic.lower(), words, loc, item.text, context)
        elif isinstance(stmt, Assignment):
            self.assignment(stmt, f"{item.file}:{item.line}")
        else:
            self.directive(stmt, item, context)

    # -- names -------------------------------------------------------------------------

    def define(self, name: str, value: Value, where: str) -> None:
        self.env[name] = value
        self.defined_at[name] = where
        number = plain_number(value)
        if number is not None:
            self.plain[name] = number
        if self.scopes:
            self.scopes[-1].append(name)

    def new_name(self, node: Operand, what: str) -> str | None:
        """The name ``node`` introduces, or None after reporting why it cannot."""
        if not isinstance(node, Ref):
            self.error(f"{what} must be a name", node.col, node.end)
            return None
        name = node.name
        if name.lower() in self.mnemonic_names:
            self.error(f"'{name}' is a mnemonic and cannot name {what}", node.col, node.end)
            return None
        if name in self.env:
            self.error(f"'{name}' is already defined (at {self.defined_at[name]})", node.col, node.end)
            return None
        return name

    def assignment(self, stmt: Assignment, where: str) -> None:
        name = self.new_name(Ref(stmt.name, stmt.col, stmt.end), "a constant")
        if name is None:
            return
        try:
            value = evaluate(stmt.expr, self.env)
        except EvalError as exc:
            self.eval_error(exc)
            value = POISON  # later uses fail quietly instead of as "undefined"
        self.define(name, value, where)

    def eval_error(self, exc: EvalError) -> None:
        if exc.message:  # an empty message: the cause was reported already
            self.error(exc.message, exc.col, exc.end)

    def evaluate(self, node: Operand) -> Value | None:
        try:
            return evaluate(node, self.env)
        except EvalError as exc:
            self.eval_error(exc)
            return None

    def integer(self, node: Operand, what: str, lo: int, limit: int) -> int | None:
        """An integer operand in [lo, limit), or None after reporting why not."""
        v = self.evaluate(node)
        if v is None:
            return None
        src = self.source(node)
        if v.raw is not None:
            self.error(f"{what} must be an integer, not raw bits '{src}'", node.col, node.end)
            return None
        if not v.is_integer:
            self.error(f"{what} must be an integer, got {src} = {describe(v.number)}", node.col, node.end)
            return None
        if not lo <= v.number < limit:
            self.error(f"{what} {describe(v.number)} is out of range ({lo}..{limit - 1})", node.col, node.end)
            return None
        return v.number

    def source(self, node: Operand) -> str:
        """The operand's text as written, cut for a message (see :func:`.parser.quote`)."""
        return quote(self.where[2][node.col - 1 : node.end - 1])

    # -- directives --------------------------------------------------------------------

    def directive(self, stmt: Directive, item: _Stmt, context: tuple[str, ...]) -> None:
        kind = stmt.name.lower()
        if kind == ".word":
            if not stmt.args:
                self.error(".word takes one or more 32-bit values", stmt.col, stmt.end)
                return
            words = [self.integer(a, ".word value", 0, WORD_LIMIT) for a in stmt.args]
            if None not in words:
                self.emit("", tuple(words), SourceLoc(item.file, item.line, stmt.col), item.text)
        elif kind == ".isa_ext":
            self.isa_ext_directive(stmt)
        elif kind == ".include":
            if len(stmt.args) != 1 or not isinstance(stmt.args[0], Str):
                self.error('.include takes one quoted path: .include "file.asm"', stmt.col, stmt.end)
                return
            self.include(stmt.args[0], item, context)
        else:
            close = difflib.get_close_matches(kind, DIRECTIVES, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            self.error(f"unknown directive '{stmt.name}'{hint}", stmt.col, stmt.end)

    def isa_ext_directive(self, stmt: Directive) -> None:
        """``.isa_ext NAME[, NAME...]``: enable ISA extensions from this line on."""
        if not stmt.args:
            self.error(f".isa_ext takes an extension name: .isa_ext {next(iter(ISA_EXTENSIONS))}", stmt.col, stmt.end)
        for arg in stmt.args:
            if not isinstance(arg, Ref):
                self.error(f".isa_ext takes extension names, not '{self.source(arg)}'", arg.col, arg.end)
                continue
            name = arg.name.lower()
            if name in ISA_EXTENSIONS:
                self.enable(name)
                continue
            close = difflib.get_close_matches(name, ISA_EXTENSIONS, n=1)
            hint = f"; did you mean '{close[0]}'?" if close else f" (known: {', '.join(ISA_EXTENSIONS)})"
            self.error(f"unknown ISA extension '{arg.name}'{hint}", arg.col, arg.end)

    def include(self, arg: Str, item: _Stmt, context: tuple[str, ...]) -> None:
        if self.include_depth >= MAX_INCLUDE_DEPTH:
            self.error(f".include nested too deeply (more than {MAX_INCLUDE_DEPTH} levels)", arg.col, arg.end)
            return
        key = (item.file, arg.text)
        if key not in self.includes:  # found once per run: a .rept does not search again
            self.includes[key] = self.find_include(arg, item)
        found = self.includes[key]
        if found is None:
            return
        path, real, text = found
        if real in self.include_stack:
            chain = " -> ".join(p.name for p in [*self.include_stack[self.include_stack.index(real):], real])
            self.error(f"include cycle: {chain}", arg.col, arg.end)
            return
        self.count_read(text, text.count("\n") + 1)
        self.include_stack.append(real)
        self.include_depth += 1
        try:
            self.run_text(text, str(path), (f"included from {item.file}:{item.line}", *context))
        finally:
            self.include_stack.pop()
            self.include_depth -= 1

    def find_include(self, arg: Str, item: _Stmt) -> tuple[Path, Path, str] | None:
        """The path, resolved path and text of an included file, or None after an error."""
        base = Path(item.file).parent
        candidates = [base / arg.text, *(d / arg.text for d in self.include_paths)]
        problem = ""
        for candidate in candidates:
            try:
                if candidate.is_file():
                    real = candidate.resolve()
                    break
            except (OSError, RuntimeError) as exc:  # a name too long, a symlink loop
                problem = problem or f": {getattr(exc, 'strerror', None) or exc}"
        else:
            self.files.setdefault(Path(os.path.abspath(candidates[0])))
            searched = ", ".join(str(p.parent) for p in candidates)
            self.error(f"cannot find include file '{quote(arg.text)}'{problem} (searched: {quote(searched)})",
                       arg.col, arg.end)
            return None
        self.files.setdefault(real)
        text = read_source(candidate, self.error_at(arg))
        return None if text is None else (candidate, real, text)

    def error_at(self, node: Operand):
        return lambda message: self.error(message, node.col, node.end)

    # -- whole program -----------------------------------------------------------------

    def finish(self, main_file: str) -> None:
        """Warnings about the program as a whole."""
        last = self.entries[-1] if self.entries else None
        self.where = (main_file, 0, "", ())
        if last is not None and last.loc is not None:
            self.where = (last.loc.file, last.loc.line, last.text, ())
        tail = [e.words for e in self.entries[-2:]]
        if tail != [(0,), (0,)]:
            self.warning("program does not end with two 'er' (the device stops at an er followed by a zero word)")
        words = self.address
        if self.target and words > self.target.instructions:
            self.where = (main_file, 0, "", ())
            self.warning(f"program is {words} words; {self.target.name} holds {self.target.instructions}")


def read_source(path: Path, error) -> str | None:
    """A source file's text (at most MAX_SOURCE bytes), or None after calling ``error(message)``."""
    try:
        data = read_limited(path, MAX_SOURCE, what="source")
    except Rend3rError as exc:
        error(str(exc))
        return None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        error(f"'{path}' is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start})")
        return None


def _result(asm: Assembler, werror: bool) -> AssemblyResult:
    diagnostics = [d.as_error() for d in asm.diagnostics] if werror else asm.diagnostics
    return AssemblyResult(Program(asm.entries), diagnostics, asm.mnemonics, asm.stopped_at, list(asm.files))


def assemble_source(
    text: str,
    filename: str = "<input>",
    include_paths: Iterable[str | os.PathLike[str]] = (),
    target: str | Target | None = None,
    *,
    werror: bool = False,
    fast: bool = True,
    isa_ext: IsaExt = (),
    max_errors: int = 0,
) -> AssemblyResult:
    """Assemble source text. ``.include`` paths are relative to ``filename``'s directory
    (the current directory for ``<input>``), then to each of ``include_paths``.
    ``isa_ext`` names ISA extensions to enable from the start (``"hybrid"``, or several;
    a source can also enable them with ``.isa_ext``). ``fast=False`` parses every line
    with the full grammar and runs .rept bodies uncompiled (for testing the fast paths). ``max_errors`` stops the run at
    that many errors (0: no limit; the result's ``stopped_at`` says it stopped).
    """
    asm = Assembler(include_paths, target, fast, isa_ext, max_errors, werror)
    try:
        if filename != "<input>":
            asm.include_stack.append(Path(filename).resolve())
            asm.files.setdefault(asm.include_stack[0])
        asm.where = (filename, 0, "", ())
        asm.count_read(text, 0)
        asm.run_text(text, filename)
    except _Abort:
        pass
    else:
        asm.finish(filename)
    return _result(asm, werror)


def assemble_file(
    path: str | os.PathLike[str],
    include_paths: Iterable[str | os.PathLike[str]] = (),
    target: str | Target | None = None,
    *,
    werror: bool = False,
    isa_ext: IsaExt = (),
    max_errors: int = 0,
) -> AssemblyResult:
    """Assemble a source file; a missing or unreadable file (or one over MAX_SOURCE
    bytes) is an error diagnostic."""
    asm = Assembler(include_paths, target, isa_ext=isa_ext)
    name = str(path)
    asm.files.setdefault(Path(os.path.abspath(path)))
    text = read_source(Path(path), lambda message: asm.diagnostics.append(Diagnostic(ERROR, message, name, 0)))
    if text is None:
        return _result(asm, werror)
    return assemble_source(text, name, include_paths, target, werror=werror, isa_ext=isa_ext, max_errors=max_errors)


def assemble_or_raise(
    path: str | os.PathLike[str],
    include_paths: Iterable[str | os.PathLike[str]] = (),
    target: str | Target | None = None,
    *,
    isa_ext: IsaExt = (),
    max_errors: int = MAX_ERRORS,
) -> AssemblyResult:
    """Assemble a file, raising :class:`Rend3rError` with every diagnostic on errors
    (the first ``max_errors`` of them; 0 for all)."""
    result = assemble_file(path, include_paths, target, isa_ext=isa_ext, max_errors=max_errors)
    if not result.ok:
        raise Rend3rError(result.format_diagnostics(), preformatted=True)
    return result
