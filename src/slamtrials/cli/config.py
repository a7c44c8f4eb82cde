"""``slamtrials config``: the campaign configuration file (``config dump`` prints the defaults)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import make_app

__all__ = ["app", "dump", "register"]

app = make_app(help="Campaign configuration: print a complete, commented default config.")


@app.command("dump")
def dump(
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Write the YAML to this file instead of printing it.")
    ] = None,
) -> None:
    """Print a complete campaign config of the defaults, every key commented (edit it, then 'campaign run')."""
    from slamtrials.atomicfile import atomic_write_text
    from slamtrials.campaign import dump_default_yaml

    text = dump_default_yaml()
    if out is None:
        typer.echo(text, nl=False)
    else:
        atomic_write_text(out, text)
        typer.echo(f"wrote {out}")


def register(root: typer.Typer) -> None:
    """Add the ``config`` command group to ``root``."""
    root.add_typer(app, name="config", help="Campaign configuration: 'config dump' prints the commented defaults.")
