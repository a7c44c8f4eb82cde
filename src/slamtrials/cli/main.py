"""The ``slamtrials`` command: the root typer app, error handling and ``--version``.

Each command group lives in its own module and is added here. The CLI alone picks the matplotlib
backend, configures logging, prints, and maps errors to exit codes: a :class:`SlamtrialsError` (or an
unreadable file) becomes one line on stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import logging
import sys
from typing import Annotated

import typer

from slamtrials.__about__ import __version__
from slamtrials.cli.common import EXIT_BAD_INPUT, ErrorReportingGroup, make_app, make_console

__all__ = ["app", "main", "make_app", "make_console", "ErrorReportingGroup", "EXIT_BAD_INPUT"]

app = make_app(help="Repeatable SLAM evaluation: simulate, explore, map, measure, repeat until confident.")


def _version(value: bool) -> None:
    if value:
        typer.echo(f"slamtrials {__version__}")
        raise typer.Exit()


#: Said once on stderr, when it is a terminal, when a command has to compile numba kernels (not found
#: in numba's cache); with --verbose every compile is logged too.
COMPILING_NOTICE = "compiling numerical kernels (first run only, up to a minute)..."


def _say_compiling(kernel: str) -> None:
    typer.echo(COMPILING_NOTICE, err=True)


@app.callback()
def root(
    ctx: typer.Context,
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
    verbose: Annotated[bool, typer.Option("--verbose", "-v", help="Log progress details to stderr.")] = False,
) -> None:
    """slamtrials: repeatable SLAM evaluation in simulated buildings."""
    import matplotlib

    from slamtrials.compilewatch import watch_compilation

    matplotlib.use("Agg")
    logging.basicConfig(
        level=logging.INFO if verbose else logging.WARNING, format="%(levelname)s %(name)s: %(message)s"
    )
    ctx.call_on_close(watch_compilation(_say_compiling if sys.stderr.isatty() else None))


def _register_commands() -> None:
    from slamtrials.cli import (
        calibrate,
        campaign,
        config,
        demo,
        evaluate,
        report,
        simulate,
        slam,
        study,
        transfer,
        trial,
        validate,
        worlds,
    )

    app.add_typer(worlds.app, name="worlds", help="List, show, load and generate floor plans.")
    simulate.register(app)
    demo.register(app)
    transfer.register(app)
    evaluate.register(app)
    slam.register(app)
    calibrate.register(app)
    trial.register(app)
    campaign.register(app)
    study.register(app)
    config.register(app)
    report.register(app)
    validate.register(app)


_register_commands()


def main() -> None:
    """Console-script entry point."""
    app()


if __name__ == "__main__":
    main()
