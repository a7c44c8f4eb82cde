"""Reference pages written from the code itself: every CLI command's help, every configuration key and
the public API.

The documentation site (``make docs``) inserts these texts where a page holds ``<!-- cli-reference -->``,
``<!-- config-reference -->`` or ``<!-- api-reference -->`` (``docs/hooks/reference.py``), so the
reference cannot drift from the commands, the pydantic models and the docstrings: a new option or key, a
changed default or range, shows up at the next build.
"""

from __future__ import annotations

import typing
from collections.abc import Iterator
from typing import Any

import typer
from pydantic import BaseModel
from pydantic.fields import FieldInfo
from typer.core import TyperGroup

__all__ = ["cli_reference", "config_reference", "api_reference", "CONFIG_MODELS"]


def _commands(command: Any, path: list[str]) -> Iterator[tuple[list[str], Any]]:
    """The command tree under ``command`` (typer's own click command objects), depth first, sorted."""
    yield path, command
    if isinstance(command, TyperGroup):
        for name in sorted(command.list_commands(None)):
            sub = command.get_command(None, name)
            if sub is not None and not sub.hidden:
                yield from _commands(sub, [*path, name])


def cli_reference(app: typer.Typer | None = None) -> str:
    """Markdown: one section per command of ``app`` (the ``slamtrials`` app by default), in tree order,
    each with its usage, help text and options exactly as ``--help`` prints them (100 columns)."""
    if app is None:
        from slamtrials.cli.main import app as main_app

        app = main_app
    from typer.testing import CliRunner

    root = typer.main.get_command(app)
    runner = CliRunner()
    out: list[str] = []
    for path, _command in _commands(root, ["slamtrials"]):
        name = " ".join(path)
        result = runner.invoke(
            app, [*path[1:], "--help"], prog_name="slamtrials", env={"COLUMNS": "100", "TERM": "dumb", "NO_COLOR": "1"}
        )
        if result.exit_code != 0:
            raise RuntimeError(f"{name} --help failed: {result.output.strip().splitlines()[-1:]}")
        text = "\n".join(line.rstrip() for line in result.output.strip().splitlines())
        level = "#" * min(len(path) + 1, 4)
        out.append(f"{level} `{name}`\n\n```text\n{text}\n```\n")
    return "\n".join(out)


#: The configuration models a user writes as YAML, with the key under which each appears.
CONFIG_MODELS: tuple[tuple[str, str], ...] = (
    ("campaign config (`slamtrials campaign run --config`)", "slamtrials.campaign.config:CampaignConfig"),
    ("trial config (`slamtrials trial --config`)", "slamtrials.trial.config:TrialConfig"),
)


def _model(spec: str) -> type[BaseModel]:
    module, name = spec.split(":")
    from importlib import import_module

    model = getattr(import_module(module), name)
    assert isinstance(model, type) and issubclass(model, BaseModel)
    return model


def _submodel(annotation: object) -> type[BaseModel] | None:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    return None


def _constraints(info: FieldInfo) -> str:
    bounds = []
    for item in info.metadata:
        for attr, sign in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            value = getattr(item, attr, None)
            if value is not None:
                bounds.append(f"{sign} {value:g}" if isinstance(value, float) else f"{sign} {value}")
    return ", ".join(bounds)


def _default(info: FieldInfo) -> str:
    if info.is_required():
        return "required"
    if info.default_factory is not None:
        value = info.default_factory()  # type: ignore[call-arg]
        return "(section)" if isinstance(value, BaseModel) else f"`{value!r}`"
    value = info.default
    if isinstance(value, float):
        return f"`{value:.6g}`"
    return f"`{value!r}`"


def _type_name(annotation: object) -> str:
    text = getattr(annotation, "__name__", None) if not typing.get_args(annotation) else None
    return text or str(annotation).replace("typing.", "")


def _rows(model: type[BaseModel], prefix: str, seen: set[type[BaseModel]]) -> Iterator[str]:
    for name, info in model.model_fields.items():
        key = f"{prefix}{name}"
        sub = _submodel(info.annotation)
        if sub is not None and sub not in seen:
            yield from _rows(sub, key + ".", seen | {sub})
            continue
        description = (info.description or "").replace("|", "\\|")
        kind = _type_name(info.annotation).replace("|", "\\|")
        yield f"| `{key}` | {kind} | {_default(info).replace('|', chr(92) + '|')} | {_constraints(info)} | {description} |"


def config_reference() -> str:
    """Markdown: for each configuration model of :data:`CONFIG_MODELS`, a table of every key (nested
    sections as dotted names) with its type, default, allowed range and description, from the pydantic
    models themselves."""
    out: list[str] = []
    for title, spec in CONFIG_MODELS:
        model = _model(spec)
        out.append(f"## {title}\n")
        out.append("| key | type | default | allowed | meaning |\n|---|---|---|---|---|")
        out.extend(_rows(model, "", {model}))
        out.append("")
    return "\n".join(out)


def api_reference() -> str:
    """Markdown: a mkdocstrings block (``::: module.name``) for every name of the public API
    (``slamtrials.__all__``), at the module that defines it, in the order ``slamtrials`` lists them."""
    import slamtrials

    out = []
    for name in slamtrials.__all__:
        if name == "__version__":
            continue
        obj = getattr(slamtrials, name)
        out.append(f"::: {obj.__module__}.{obj.__qualname__}\n")
    return "\n".join(out)
