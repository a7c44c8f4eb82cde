"""The SLAM plug-in interface: the :class:`SlamAlgorithm` protocol, the map type and the registry.

A SLAM algorithm is a class with

* ``name``: the registry name (``slamtrials slam --algorithm NAME``);
* ``Config``: a pydantic model of its parameters (SI units), every field with a default;
* ``PRESETS``: named parameter sets, ``{preset name: {parameter: value}}`` (may be empty);
* a constructor ``Algorithm(config, laser)`` taking a validated ``Config`` and the laser geometry
  of :class:`~slamtrials.record.RunRecord` (``angle_min``, ``angle_increment``, ``range_min``,
  ``range_max``, ``mount``);
* ``reset(rng)``, ``process(frame) -> pose``, ``occupancy()``, ``trajectory()`` and an ``updates``
  counter (see :class:`SlamAlgorithm`).

Built-in algorithms are listed in :data:`ALGORITHMS`; :func:`register_algorithm` adds one at run time,
and third-party packages publish theirs under the entry-point group ``slamtrials.slam``
(``[project.entry-points."slamtrials.slam"] myslam = "mypkg.module:MySlam"``).
:func:`make_algorithm` validates a configuration (preset, then overrides) and builds an instance.
"""

from __future__ import annotations

from importlib.metadata import entry_points
from typing import Any, ClassVar, Protocol, TypeVar, cast, runtime_checkable

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ValidationError

from slamtrials.cost import ProcessUsage
from slamtrials.errors import ConfigError
from slamtrials.record import FREE, OCCUPIED, UNKNOWN, LaserGeometry, OccupancyGrid, Reading, Trajectory

__all__ = [
    "OccupancyGrid",
    "SlamAlgorithm",
    "ChildProcessAlgorithm",
    "ALGORITHMS",
    "ENTRY_POINT_GROUP",
    "register_algorithm",
    "get_algorithm",
    "known_algorithms",
    "resolve_config",
    "make_algorithm",
    "OCCUPIED",
    "FREE",
    "UNKNOWN",
]

#: Entry-point group under which other packages publish SLAM algorithm classes.
ENTRY_POINT_GROUP = "slamtrials.slam"


@runtime_checkable
class SlamAlgorithm(Protocol):
    """What every SLAM algorithm offers (structural: no base class needed).

    Attributes
    ----------
    name:
        Registry name (class attribute).
    Config:
        pydantic model of the parameters (class attribute); every field has a default.
    PRESETS:
        ``{preset name: {parameter: value}}`` (class attribute, may be empty).
    updates:
        Number of map (or filter) updates done since the last :meth:`reset`.

    An instance is built as ``Algorithm(config, laser)`` with a validated ``Config`` and the laser
    geometry (:class:`~slamtrials.record.LaserGeometry`).
    """

    name: ClassVar[str]
    Config: ClassVar[type[BaseModel]]
    PRESETS: ClassVar[dict[str, dict[str, Any]]]
    updates: int

    def __init__(self, config: Any, laser: LaserGeometry) -> None:
        """Build from a validated ``Config`` instance (typed ``Any``: each class takes its own model)."""
        ...

    def reset(self, rng: np.random.Generator) -> None:
        """Forget every processed frame; later random draws come from ``rng``."""
        ...

    def process(self, frame: Reading) -> NDArray[np.float64]:
        """Take one reading (time, ranges, odometry: never the ground truth); return the current pose
        estimate of the robot base, float64 ``[3]``, map frame."""
        ...

    def occupancy(self) -> OccupancyGrid:
        """The current map."""
        ...

    def trajectory(self) -> Trajectory:
        """Timestamps (s) and pose estimates (map frame) of every frame processed since :meth:`reset`."""
        ...


@runtime_checkable
class ChildProcessAlgorithm(Protocol):
    """An algorithm that does its work in a child process (an external program run online): what that
    process used is its cost, not the CPU time and memory of the calls into this object."""

    def child_usage(self) -> ProcessUsage | None:
        """What the child process started since the last ``reset`` used, once it has exited (after
        ``trajectory()``); None before that, or when it was killed."""
        ...


#: Built-in (and run-time registered) algorithms: name -> class.
ALGORITHMS: dict[str, type[SlamAlgorithm]] = {}

_CONTRACT = ("name", "Config", "PRESETS", "reset", "process", "occupancy", "trajectory")

#: Any class may be registered (``type[Any]``: its attributes are unknown until checked below).
_Class = TypeVar("_Class", bound="type[Any]")


def register_algorithm(cls: _Class) -> _Class:
    """Add ``cls`` to :data:`ALGORITHMS` under ``cls.name`` and return it (usable as a decorator).

    Raises
    ------
    ConfigError
        ``cls`` lacks part of the :class:`SlamAlgorithm` contract, its ``Config`` is not a pydantic model,
        or its ``PRESETS`` is not a dict of dicts.
    """
    checked = _checked(cls)
    ALGORITHMS[checked.name] = checked
    return cls


def _checked(cls: Any) -> type[SlamAlgorithm]:
    """``cls`` when it meets the :class:`SlamAlgorithm` contract (else ConfigError naming what it lacks)."""
    if not isinstance(cls, type):
        raise ConfigError(f"{cls!r} is not a SLAM algorithm class")
    missing = [member for member in _CONTRACT if member not in dir(cls)]
    if missing:
        raise ConfigError(
            f"SLAM algorithm class {cls.__qualname__} lacks {', '.join(missing)} (see slamtrials.slam.SlamAlgorithm)"
        )
    name, config, presets = (getattr(cls, member) for member in ("name", "Config", "PRESETS"))
    if not isinstance(name, str) or not name:
        raise ConfigError(f"SLAM algorithm class {cls.__qualname__}: name must be a non-empty string, got {name!r}")
    if not (isinstance(config, type) and issubclass(config, BaseModel)):
        raise ConfigError(f"SLAM algorithm {name!r}: Config must be a pydantic BaseModel subclass")
    if not isinstance(presets, dict) or not all(isinstance(v, dict) for v in presets.values()):
        raise ConfigError(f"SLAM algorithm {name!r}: PRESETS must map preset names to parameter dicts")
    # Checked above: the class now meets the SlamAlgorithm contract.
    return cast("type[SlamAlgorithm]", cls)


def _entry_points() -> dict[str, Any]:
    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def known_algorithms() -> list[str]:
    """Sorted names of the registered and entry-point algorithms."""
    return sorted(set(ALGORITHMS) | set(_entry_points()))


def get_algorithm(name: str) -> type[SlamAlgorithm]:
    """The algorithm class called ``name``: registered, published under :data:`ENTRY_POINT_GROUP`, or
    named by reference: ``package.module:Class`` (an importable module) or ``path/to/file.py:Class``.

    An entry-point or referenced class is checked and registered (under ``name``) on first use.

    Raises
    ------
    ConfigError
        No algorithm has that name (the message lists the known ones), or its entry point fails to load.
    """
    if name in ALGORITHMS:
        return ALGORITHMS[name]
    if ":" in name:
        try:
            ALGORITHMS[name] = _checked(_load_reference(name))
        except ConfigError as exc:
            raise ConfigError(str(exc) if str(exc).startswith("SLAM algorithm") else f"{name!r}: {exc}") from None
        return ALGORITHMS[name]
    found = _entry_points().get(name)
    if found is None:
        raise ConfigError(f"unknown SLAM algorithm {name!r}; known: {', '.join(known_algorithms()) or 'none'}")
    try:
        cls = found.load()
    except Exception as exc:  # a third-party import error must not become a traceback
        raise ConfigError(f"SLAM algorithm {name!r} (entry point {found.value}) failed to load: {exc}") from None
    if not isinstance(cls, type) or cls.__dict__.get("name", name) != name:
        raise ConfigError(f"entry point {name!r} = {found.value} is not a SLAM algorithm class named {name!r}")
    register_algorithm(cls)
    return cast("type[SlamAlgorithm]", cls)  # register_algorithm checked the contract


def _load_reference(reference: str) -> Any:
    """The class ``reference`` names: ``package.module:Class`` (importable) or ``path/to/file.py:Class``.

    Raises
    ------
    ConfigError
        The module or file cannot be loaded, or holds no such attribute.
    """
    import hashlib
    import importlib
    import importlib.util
    import sys
    from pathlib import Path

    where, _, attribute = reference.rpartition(":")
    if not where or not attribute.isidentifier():
        raise ConfigError(f"SLAM algorithm {reference!r}: expected 'package.module:Class' or 'file.py:Class'")
    try:
        if where.endswith(".py") or "/" in where or "\\" in where:
            path = Path(where).expanduser().absolute()
            if not path.is_file():
                raise ConfigError(f"SLAM algorithm {reference!r}: no such file {path}")
            module_name = "slamtrials_plugin_" + hashlib.sha1(str(path).encode()).hexdigest()[:12]
            spec = importlib.util.spec_from_file_location(module_name, path)
            if spec is None or spec.loader is None:
                raise ConfigError(f"SLAM algorithm {reference!r}: {path} is not a Python file")
            module = importlib.util.module_from_spec(spec)
            sys.modules[module_name] = module
            spec.loader.exec_module(module)
        else:
            module = importlib.import_module(where)
    except ConfigError:
        raise
    except Exception as exc:  # a plug-in's import error must not become a traceback
        raise ConfigError(f"SLAM algorithm {reference!r} failed to load: {type(exc).__name__}: {exc}") from None
    if not hasattr(module, attribute):
        raise ConfigError(f"SLAM algorithm {reference!r}: {where} has no {attribute!r}")
    return getattr(module, attribute)


def _allowed(model: type[BaseModel], parameter: str) -> str:
    """Human-readable bounds of one field (from its Gt/Ge/Lt/Le constraints), or ''."""
    field = model.model_fields.get(parameter)
    if field is None:
        return ""
    words = []
    for item in field.metadata:
        for attr, symbol in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            value = getattr(item, attr, None)
            if value is not None and type(item).__name__.lower() in (attr, "interval"):
                words.append(f"{symbol} {value:g}" if isinstance(value, (int, float)) else f"{symbol} {value}")
    return f"; allowed: {' and '.join(words)}" if words else ""


def resolve_config(
    cls: type[SlamAlgorithm], *, preset: str | None = None, overrides: dict[str, Any] | None = None
) -> BaseModel:
    """Validate ``cls.Config`` from the defaults, then preset ``preset``, then ``overrides``.

    Raises
    ------
    ConfigError
        An unknown preset (listing the presets), an unknown parameter (listing the parameters), or a
        value the model rejects (naming the parameter, the value and the allowed range).
    """
    values: dict[str, Any] = {}
    if preset is not None:
        if preset not in cls.PRESETS:
            known = ", ".join(sorted(cls.PRESETS)) or "none"
            raise ConfigError(f"SLAM algorithm {cls.name!r} has no preset {preset!r}; presets: {known}")
        values.update(cls.PRESETS[preset])
    values.update(overrides or {})
    fields = cls.Config.model_fields
    unknown = sorted(set(values) - set(fields))
    if unknown:
        raise ConfigError(
            f"SLAM algorithm {cls.name!r} has no parameter {', '.join(unknown)}; parameters: {', '.join(fields)}"
        )
    try:
        return cls.Config.model_validate(values)
    except ValidationError as exc:
        problems = []
        for err in exc.errors():
            parameter = ".".join(str(p) for p in err["loc"]) or "<config>"
            top = str(err["loc"][0]) if err["loc"] else ""
            shown = f" = {err['input']!r}" if top in values else ""
            problems.append(f"{parameter}{shown}: {err['msg']}{_allowed(cls.Config, top)}")
        raise ConfigError(f"SLAM algorithm {cls.name!r}: " + "; ".join(problems)) from None


def make_algorithm(
    name: str, laser: LaserGeometry, *, preset: str | None = None, overrides: dict[str, Any] | None = None
) -> SlamAlgorithm:
    """Build algorithm ``name`` for a laser of geometry ``laser`` with a validated configuration.

    Parameters
    ----------
    name:
        Registry or entry-point name.
    laser:
        The laser's geometry (:class:`~slamtrials.record.LaserGeometry`).
    preset:
        Name of one of the class's :data:`PRESETS`, applied over the defaults.
    overrides:
        ``{parameter: value}`` applied last.

    Raises
    ------
    ConfigError
        See :func:`get_algorithm` and :func:`resolve_config`.
    """
    cls = get_algorithm(name)
    return cls(resolve_config(cls, preset=preset, overrides=overrides), laser)
