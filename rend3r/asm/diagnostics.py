"""Assembler diagnostics: ``file:line:col: error: message``, the line, a caret span."""

from __future__ import annotations

from dataclasses import dataclass

ERROR = "error"
WARNING = "warning"
#: Longest source line shown whole under a diagnostic; a longer one is shown as a window
#: of this many characters around the span.
SHOWN_LINE = 160


@dataclass(frozen=True)
class Diagnostic:
    """One error or warning at a span of a source line.

    ``context`` lists where the line was reached from, innermost first (``in .rept
    iteration i=3 (a.asm:5)``, ``included from main.asm:4``).
    """

    severity: str
    message: str
    file: str
    line: int
    col: int = 1
    end: int = 0  # column after the span; 0 or <= col underlines one character
    text: str = ""  # the source line; empty when there is none to show
    context: tuple[str, ...] = ()

    @property
    def is_error(self) -> bool:
        return self.severity == ERROR

    def as_error(self) -> "Diagnostic":
        """This diagnostic promoted to an error (``-W error``)."""
        if self.is_error:
            return self
        return Diagnostic(ERROR, f"{self.message} [-W error]", self.file, self.line, self.col, self.end,
                          self.text, self.context)

    def format(self) -> str:
        """The diagnostic as printed: header, source line and caret line, then context."""
        where = f"{self.file}:{self.line}:{self.col}" if self.line else self.file
        out = [f"{where}: {self.severity}: {self.message}"]
        if self.text.strip():
            text, col, end = window(self.text, self.col, self.end)
            out.append("    " + text)
            out.append("    " + caret_line(text, col, end))
        out.extend(f"    {c}" for c in self.context)
        return "\n".join(out)


def window(text: str, col: int, end: int) -> tuple[str, int, int]:
    """At most about SHOWN_LINE characters of ``text`` around columns [col, end), with
    ``...`` where it was cut, and the span's columns in the result."""
    if len(text) <= SHOWN_LINE:
        return text, col, end
    start = max(min(col - 1 - SHOWN_LINE // 4, len(text) - SHOWN_LINE), 0)
    stop = start + SHOWN_LINE
    head = "..." if start else ""
    shown = head + text[start:stop] + ("..." if stop < len(text) else "")
    shift = len(head) - start
    return shown, col + shift, min(end, stop + 1) + shift


def caret_line(text: str, col: int, end: int) -> str:
    """``^~~~`` under columns [col, end) of ``text``; tabs before the span are kept so the
    caret lines up however the terminal expands them."""
    prefix = "".join(c if c == "\t" else " " for c in text[: max(col - 1, 0)])
    width = max(end - col, 1)
    return prefix + "^" + "~" * (width - 1)


def format_all(diagnostics: list[Diagnostic]) -> str:
    """All diagnostics, then a count line (``2 errors, 1 warning``) when there are any."""
    if not diagnostics:
        return ""
    errors = sum(d.is_error for d in diagnostics)
    warnings = len(diagnostics) - errors
    parts = []
    if errors:
        parts.append(f"{errors} error{'s' if errors != 1 else ''}")
    if warnings:
        parts.append(f"{warnings} warning{'s' if warnings != 1 else ''}")
    return "\n".join(d.format() for d in diagnostics) + "\n" + ", ".join(parts) + " generated."
