"""What every command module shares: the error-reporting group, the app factory and the console.

Kept apart from :mod:`slamtrials.cli.main` (which imports every command module to register it) so that
a command module can be imported on its own without a circular import.
"""

from __future__ import annotations

import logging

import typer
from typer import BadParameter
from typer.core import TyperGroup

try:  # typer >= 0.20 carries its own copy of click
    from typer._click.exceptions import MissingParameter
except ImportError:  # pragma: no cover - older typer on click
    from click.exceptions import MissingParameter

from slamtrials.errors import SlamtrialsError

__all__ = [
    "EXIT_BAD_INPUT",
    "ErrorReportingGroup",
    "make_app",
    "make_console",
    "quiet_dask",
    "profile_line",
    "sim_profile_line",
    "say_profile",
]

EXIT_BAD_INPUT = 2


def _fold_long_words_in_help() -> None:
    """Make typer's help fold a word too long for its column instead of cutting it with an ellipsis (a
    path such as ``/base_pose_ground_truth`` in a narrow terminal): the columns its tables create as rows
    are added, and the texts of an option's help cell, get rich's ``overflow="fold"``."""
    from rich.table import Table
    from rich.text import Text
    from typer import rich_utils

    if getattr(rich_utils.Table, "folds_long_words", False):
        return

    class FoldingTable(Table):
        folds_long_words = True

        def add_row(self, *renderables, **kwargs):
            while len(self.columns) < len(renderables):
                self.add_column(overflow="fold")
            super().add_row(*renderables, **kwargs)

    class FoldingColumns(rich_utils.Columns):  # type: ignore[name-defined,misc]
        def __init__(self, renderables=None, *args, **kwargs):
            items = list(renderables or [])
            for item in items:
                if isinstance(item, Text):
                    item.overflow = "fold"
            super().__init__(items, *args, **kwargs)

    rich_utils.Table = FoldingTable  # type: ignore[misc]
    rich_utils.Columns = FoldingColumns  # type: ignore[misc]


_fold_long_words_in_help()


class ErrorReportingGroup(TyperGroup):
    """A command group that turns expected errors into one line and exit status 2.

    A bad option or argument value (an unknown choice, a number that does not parse) is one line too,
    like the values the commands check themselves; usage mistakes (a missing or unknown option) keep
    typer's usage panel, which points to --help.
    """

    def get_params(self, ctx):
        return _flags_as_flags(super().get_params(ctx))

    def get_command(self, ctx, cmd_name):
        command = super().get_command(ctx, cmd_name)
        if command is not None and ctx is not None:  # the reference walks the tree without a context
            _flags_as_flags(command.get_params(ctx))
        if command is not None and command.help:
            command.help = reflow(command.help)
        return command

    def invoke(self, ctx):  # ctx: typer's (vendored) click Context
        try:
            return super().invoke(ctx)
        except BadParameter as exc:
            if isinstance(exc, MissingParameter):
                raise
            typer.echo(f"error: {bad_value_line(exc)}", err=True)
            raise typer.Exit(EXIT_BAD_INPUT) from None
        except SlamtrialsError as exc:
            typer.echo(f"error: {exc}", err=True)
            raise typer.Exit(EXIT_BAD_INPUT) from None
        except OSError as exc:  # missing, unreadable or unwritable files named on the command line
            where = f"{exc.filename}: " if exc.filename else ""
            typer.echo(f"error: {where}{exc.strerror or exc}", err=True)
            raise typer.Exit(EXIT_BAD_INPUT) from None
        except KeyboardInterrupt:  # commands that can resume say how themselves, before this
            typer.echo("interrupted", err=True)
            raise typer.Exit(130) from None


def _flags_as_flags(params: list) -> list:
    """Show boolean flags in the help as flags: typer's rich help prints a type after every option
    (``--overwrite <bool>``), which reads as if the flag took a value (``--overwrite true`` fails).
    An empty metavar leaves the type column empty for them."""
    for param in params:
        if getattr(param, "is_flag", False) and param.metavar is None:
            param.metavar = ""
    return params


def _is_prose(paragraph: list[str]) -> bool:
    """Whether a help paragraph's lines are running text (not a list, a table or an indented block)."""
    for line in paragraph:
        stripped = line.lstrip()
        if (
            line != stripped
            or stripped[:2] in ("- ", "* ", "| ")
            or stripped[:1] == "\b"
            or stripped[:2].rstrip(".").isdigit()
        ):
            return False
    return True


def reflow(text: str) -> str:
    """A docstring's paragraphs as single lines, so the help wraps them to the terminal: typer keeps a
    docstring's line breaks, which leaves ragged lines in any width but the source's. Lists, tables
    and indented blocks keep their lines."""
    paragraphs = [p.split("\n") for p in text.strip().split("\n\n")]
    return "\n\n".join(" ".join(line.strip() for line in p) if _is_prose(p) else "\n".join(p) for p in paragraphs)


def bad_value_line(exc: BadParameter) -> str:
    """``--to: 'xyz' is not one of 'bag', 'bag2', 'carmen', 'tum'.``: the option (its long name) or the
    argument (its metavar) and typer's reason, without the "Value error, " its validation prefixes."""
    param = exc.param
    if param is None:
        name = exc.param_hint if isinstance(exc.param_hint, str) else ""
    elif param.param_type_name == "option":
        name = max(param.opts, key=len)
    else:
        name = param.human_readable_name
    reason = " ".join(exc.message.split()).removeprefix("Value error, ").rstrip(".")
    return f"{name}: {reason}" if name else reason


def make_app(**kwargs) -> typer.Typer:
    """A typer app with slamtrials' defaults (error reporting, no shell-completion options)."""
    return typer.Typer(cls=ErrorReportingGroup, add_completion=False, no_args_is_help=True, **kwargs)


def make_console():
    """A rich Console for command output; pipes and logs get 110 columns instead of rich's default 80.

    Markup is off: the output holds paths, values and messages that may contain ``[...]`` (a config's
    ``[0.1, 0.2]``, a folder named ``runs[2]``), which rich would otherwise take for style tags and drop.
    """
    from rich.console import Console

    console = Console(markup=False)
    return console if console.is_terminal else Console(width=110, markup=False)


def fmt_number(value: float | None, digits: int = 3) -> str:
    """``value`` with ``digits`` decimals, or ``-`` for None and NaN (a table cell)."""
    return "-" if value is None or value != value else f"{value:.{digits}f}"


def table_one(title: str, confidence: float, last_column: str, last_justify: str = "left"):
    """An empty rich Table with the paper's Table I columns (world, status, runs, eps_t and eps_r each
    with std and confidence half width) and ``last_column`` (aligned ``last_justify``); rows are added
    by the caller."""
    from rich.table import Table

    table = Table(
        title=title,
        caption=f"eps_t in m, eps_r in rad: mean and sample std over the runs; +-: half width "
        f"of the {100 * confidence:g} % confidence interval of the mean",
    )
    table.add_column("world", no_wrap=True)
    table.add_column("status")
    table.add_column("runs", justify="right")
    for column in ("eps_t", "std", "+-", "eps_r", "std", "+-"):
        table.add_column(column, justify="right", no_wrap=True)
    table.add_column(last_column, justify=last_justify)
    return table


def profile_line(label: str, keys: tuple[str, ...] = ()) -> str:
    """``profile: realistic``, or ``profile: realistic + 2 overrides (laser.dropout_rate, ...)``: the line
    every command that simulates prints (``label`` from :attr:`slamtrials.sim.SimConfig.profile_label`)."""
    return f"profile: {label}" + (f" ({', '.join(keys)})" if keys else "")


def sim_profile_line(sim) -> str:
    """:func:`profile_line` of the simulation config ``sim`` (a :class:`~slamtrials.sim.SimConfig`, or an
    :class:`~slamtrials.sim.profiles.ErrorProfile` used as it is)."""
    from slamtrials.sim import SimConfig

    if isinstance(sim, SimConfig):
        return profile_line(sim.profile_label, tuple(o.key for o in sim.profile_overrides))
    return profile_line(sim.name)


def say_profile(sim) -> None:
    """Print :func:`sim_profile_line` of ``sim`` on stderr (before the work starts)."""
    typer.echo(sim_profile_line(sim), err=True)


def quiet_dask() -> None:
    """Dask's loggers log at INFO by default; follow the root logger's level instead (``-v`` shows them)."""
    import distributed  # noqa: F401  (its import applies dask's logging config, which we then override)

    level = logging.getLogger().getEffectiveLevel()
    if level > logging.INFO:
        for name in ("distributed", "dask"):
            logging.getLogger(name).setLevel(level)
