"""Progress bars on stderr for long work, with one look in every command.

Built on ``click.progressbar`` (label, bar, percentage, time left). A bar is drawn only
when stderr is a terminal and the user did not ask for quiet (``-q``): piped or logged
runs, and tests, see nothing. Work whose length is known up front reports units done
(rays, candidate voxels, design points); when its ``with`` block ends, however it ends
(done, an error, Ctrl-C), the bar stops where it is and the cursor moves to a new line.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from types import TracebackType
from typing import TextIO

import click


class Progress:
    """One bar over ``total`` units of work; a silent no-op when it is not shown."""

    def __init__(self, total: int, label: str, *, quiet: bool = False, file: TextIO | None = None) -> None:
        stream = sys.stderr if file is None else file
        self._bar = None
        if not quiet and stream.isatty() and total > 0:
            self._bar = click.progressbar(length=total, label=label, file=stream)

    @property
    def shown(self) -> bool:
        """Whether this bar draws anything."""
        return self._bar is not None

    def advance(self, units: int) -> None:
        """Count ``units`` more of the work as done."""
        if self._bar is not None:
            self._bar.update(units)

    def __enter__(self) -> Progress:
        if self._bar is not None:
            self._bar.render_progress()
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 tb: TracebackType | None) -> None:
        if self._bar is not None:
            self._bar.render_finish()


ProgressFactory = Callable[[int, str], Progress]
"""What library code takes to report progress: ``factory(total, label)`` -> a :class:`Progress`
(``functools.partial(Progress, quiet=quiet)`` in a command; :func:`hidden` by default)."""


def hidden(total: int, label: str) -> Progress:
    """A bar that draws nothing: the default where a caller asks for no progress."""
    return Progress(total, label, quiet=True)


def quiet_option(function):
    """``-q/--quiet``: the option every long-running command takes to hide its progress."""
    return click.option("-q", "--quiet", is_flag=True,
                        help="No progress bar and no summary line (errors are still reported).")(function)
