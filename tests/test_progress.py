"""rend3r.progress: a bar on a terminal only, silenced by quiet, the same look as click's."""

import io

import click
from click.testing import CliRunner

from rend3r.progress import Progress, quiet_option


class Terminal(io.StringIO):
    """A text stream that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def test_a_terminal_gets_a_bar_that_reaches_100_percent():
    term = Terminal()
    with Progress(4, "tracing", file=term) as bar:
        assert bar.shown
        for _ in range(4):
            bar.advance(1)
    text = term.getvalue()
    assert "tracing" in text and "100%" in text and "#" in text
    assert text.endswith("\n")  # the cursor leaves the bar's line


def test_nothing_is_written_when_the_stream_is_not_a_terminal():
    pipe = io.StringIO()
    with Progress(4, "tracing", file=pipe) as bar:
        bar.advance(4)
    assert not bar.shown and pipe.getvalue() == ""


def test_quiet_silences_a_terminal():
    term = Terminal()
    with Progress(4, "tracing", quiet=True, file=term) as bar:
        bar.advance(4)
    assert not bar.shown and term.getvalue() == ""


def test_no_work_draws_no_bar():
    term = Terminal()
    with Progress(0, "tracing", file=term) as bar:
        pass
    assert not bar.shown and term.getvalue() == ""


def test_an_interrupted_bar_still_ends_its_line():
    term = Terminal()
    try:
        with Progress(10, "tracing", file=term) as bar:
            bar.advance(3)
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    assert "30%" in term.getvalue() and term.getvalue().endswith("\n")


def test_quiet_option_is_dash_q():
    @click.command()
    @quiet_option
    def cmd(quiet: bool) -> None:
        click.echo(f"quiet={quiet}")

    assert CliRunner().invoke(cmd, ["-q"]).output == "quiet=True\n"
    assert CliRunner().invoke(cmd, ["--quiet"]).output == "quiet=True\n"
    assert CliRunner().invoke(cmd, []).output == "quiet=False\n"
