"""The ``slamtrials`` command: the root typer app, error handling and ``--version``.

Each command group lives in its own module and is added here. The CLI alone picks the matplotlib
backend, configures logging, prints, and maps errors to exit codes: a :class:`SlamtrialsError` (or an
unreadable file) becomes one line on stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import logging
from typing import Annotated

import typer
from typer.core import TyperGroup

from slamtrials.__about__ import __version__
from slamtrials.errors import SlamtrialsError

EXIT_BAD_INPUT = 2


class ErrorReportingGroup(TyperGroup):
    """A command group that turns expected errors into one line and exit status 2."""

    def invoke(self, ctx):  # ctx: typer's (vendored) click Context
        try:
            return super().invoke(ctx)
        except SlamtrialsError as exc:
            typer.echo(f"error: {exc}", err=True)
            raise typer.Exit(EXIT_BAD_INPUT) from None
        except OSError as exc:  # missing, unreadable or unwritable files named on the command line
            where = f"{exc.filename}: " if exc.filename else ""
            typer.echo(f"error: {where}{exc.strerror or exc}", err=True)
            raise typer.Exit(EXIT_BAD_INPUT) from None


def make_app(**kwargs) -> typer.Typer:
    """A typer app with slamtrials' defaults (error reporting, no shell-completion options)."""
    return typer.Typer(cls=ErrorReportingGroup, add_completion=False, no_args_is_help=True, **kwargs)


app = make_app(help="Repeatable SLAM evaluation: simulate, explore, map, measure, repeat until confident.")


def make_console():
    """A rich Console for command output; pipes and logs get 110 columns instead of rich's default 80."""
    from rich.console import Console

    console = Console()
    return console if console.is_terminal else Console(width=110)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"slamtrials {__version__}")
        raise typer.Exit()


@app.callback()
def root(
    version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")] = False,
    verbose: Annotated[bool, typer.Option("--verbose", "-v", help="Log progress details to stderr.")] = False,
) -> None:
    """slamtrials: repeatable SLAM evaluation in simulated buildings."""
    import matplotlib

    matplotlib.use("Agg")
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING, format="%(levelname)s %(name)s: %(message)s")


def _register_commands() -> None:
    from slamtrials.cli import demo, simulate, worlds
    from slamtrials.cli import transfer
    from slamtrials.cli import evaluate
    from slamtrials.cli import slam
    from slamtrials.cli import trial
    from slamtrials.cli import campaign, config

    app.add_typer(worlds.app, name="worlds", help="List, show, load and generate floor plans.")
    simulate.register(app)
    demo.register(app)
    transfer.register(app)
    evaluate.register(app)
    slam.register(app)
    trial.register(app)
    campaign.register(app)
    config.register(app)


_register_commands()


def main() -> None:
    """Console-script entry point."""
    app()
