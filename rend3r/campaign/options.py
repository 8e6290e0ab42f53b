"""``--scheduler``: the option of every command that runs a campaign."""

from __future__ import annotations

import click


class SchedulerType(click.ParamType):
    """``local``, ``none`` or ``tcp://HOST:PORT`` (anything else exits 2)."""

    name = "ADDRESS"

    def convert(self, value, param, ctx) -> str:
        from .runner import parse_scheduler

        try:
            return parse_scheduler(str(value))
        except ValueError as exc:
            self.fail(str(exc), param, ctx)


#: ``--scheduler ADDRESS``: where a campaign's tasks run (docs/campaigns.md).
SCHEDULER = click.option(
    "--scheduler", type=SchedulerType(), default="local", show_default=True,
    help="Where the tasks run: local (a Dask cluster in this process, a worker per core), tcp://HOST:PORT "
         "(an existing Dask scheduler), or none (one after another here; also when Dask is not installed).")
