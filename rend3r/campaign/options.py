"""``--scheduler``: the option of every command that runs a campaign."""

from __future__ import annotations

import click

from ..cliutil import CheckedType


#: ``--scheduler ADDRESS``: where a campaign's tasks run (docs/campaigns.md).
SCHEDULER = click.option(
    "--scheduler", type=CheckedType("ADDRESS", "rend3r.campaign.runner:parse_scheduler"), default="local",
    show_default=True,
    help="Where the tasks run: local (a Dask cluster in this process, a worker per core), tcp://HOST:PORT "
         "(an existing Dask scheduler), or none (one after another here; also when Dask is not installed).")
