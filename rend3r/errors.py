"""User-facing errors: reported by the CLI as one clear message and exit status 1."""

from __future__ import annotations


class Rend3rError(Exception):
    """An error caused by the user's input or environment, never a bug.

    The CLI prints ``rend3r: error: <message>`` (the message may already carry a
    ``file:line:col:`` prefix) and exits with ``exit_code``; no traceback is shown.
    """

    exit_code = 1
    #: True when the message is already complete diagnostics (``file:line:col: error: ...``
    #: with source lines and carets): the CLI prints it as it is, without its own prefix.
    preformatted = False

    def __init__(self, message: str, exit_code: int | None = None, *, preformatted: bool = False) -> None:
        super().__init__(message)
        if exit_code is not None:
            self.exit_code = exit_code
        self.preformatted = preformatted
