"""The layer rule of DESIGN.md and the library-wide conventions, checked on the source tree."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "slamtrials"

#: Modules every layer may import: they hold no behaviour of any layer.
UTILITIES = {"errors", "atomicfile", "__about__", "stablemath", "seeding"}

#: Layer -> the slamtrials layers it may import (DESIGN.md, "Layers").
ALLOWED = {
    "geometry": set(),
    "record": {"geometry"},
    "worlds": {"geometry"},
    "sim": {"geometry", "record", "worlds"},
    "slam": {"geometry", "record"},
    "explore": {"geometry", "record"},
    "trial": {"geometry", "record", "worlds", "sim", "slam", "explore"},
    "metric": {"geometry", "record"},
    "io": {"geometry", "record", "worlds"},
    "campaign": {"geometry", "record", "worlds", "sim", "slam", "explore", "trial", "metric", "io"},
    "report": {"geometry", "record", "worlds", "metric", "io", "campaign"},
}
#: Top-level modules that compose layers like the CLI does (no layer may import them).
COMPOSERS = {"demo", "evaluation", "slamrun", "cli", "__init__"}

#: Layers that must not do I/O, print or plot (DESIGN.md).
COMPUTING = {"geometry", "record", "sim", "slam", "explore", "trial", "metric"}

#: numpy functions whose float64 results depend on the machine: numpy's own SIMD code for these on
#: AVX-512 CPUs differs from the C library's by a few ulp, and BLAS picks its kernels by CPU.
MACHINE_DEPENDENT = {"sin", "cos", "tan", "arcsin", "arccos", "arctan", "arctan2", "hypot", "sinh", "cosh", "tanh",
                     "arcsinh", "arccosh", "arctanh", "exp", "exp2", "expm1", "log", "log2", "log10", "log1p",
                     "power", "float_power", "cbrt", "dot", "vdot", "inner", "matmul", "tensordot", "einsum", "linalg"}
#: Layers whose numbers end up in runs, maps and files, and must be the same on every machine.
REPRODUCIBLE = COMPUTING | {"worlds", "io", "campaign"}


def _layer_of(path: Path) -> str:
    relative = path.relative_to(PACKAGE)
    return relative.parts[0].removesuffix(".py")


def _imported_layers(tree: ast.AST) -> set[str]:
    layers = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module]
        else:
            continue
        for name in names:
            parts = name.split(".")
            if parts[0] == "slamtrials" and len(parts) > 1:
                layers.add(parts[1])
    return layers


SOURCES = sorted(PACKAGE.rglob("*.py"))


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_layer_imports_only_layers_above_it(path: Path) -> None:
    layer = _layer_of(path)
    if layer in COMPOSERS:
        return
    assert layer in ALLOWED or layer in UTILITIES, f"{path}: module outside the layers of DESIGN.md"
    allowed = ALLOWED.get(layer, set()) | UTILITIES | {layer}
    imported = _imported_layers(ast.parse(path.read_text(encoding="utf-8")))
    assert imported <= allowed, f"{path}: layer '{layer}' imports {sorted(imported - allowed)}"


@pytest.mark.parametrize("path", [p for p in SOURCES if _layer_of(p) != "cli"], ids=lambda p: str(p.relative_to(PACKAGE)))
def test_library_code_never_prints_exits_or_uses_global_random_state(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            if isinstance(func, ast.Name):
                assert func.id not in {"print", "input", "exit"}, f"{path}:{node.lineno}: calls {func.id}()"
            text = ast.unparse(func)
            assert text not in {"sys.exit", "os._exit"}, f"{path}:{node.lineno}: calls {text}()"
            # np.random.<draw>() uses hidden global state; only Generator / SeedSequence construction is allowed.
            if text.startswith(("np.random.", "numpy.random.")):
                assert text.split(".")[-1] in {"default_rng", "SeedSequence", "Generator", "PCG64"}, (
                    f"{path}:{node.lineno}: {text}() uses the global random state; take an rng instead"
                )
            assert not text.startswith("random."), f"{path}:{node.lineno}: uses the random module's global state"


@pytest.mark.parametrize("path", [p for p in SOURCES if _layer_of(p) in COMPUTING], ids=lambda p: str(p.relative_to(PACKAGE)))
def test_computing_layers_do_no_file_io_or_plotting(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            assert node.func.id != "open", f"{path}:{node.lineno}: opens a file"
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            module = node.module if isinstance(node, ast.ImportFrom) else node.names[0].name
            assert not (module or "").startswith(("matplotlib", "PIL")), f"{path}:{node.lineno}: imports {module}"


@pytest.mark.parametrize("path", [p for p in SOURCES if _layer_of(p) in REPRODUCIBLE],
                         ids=lambda p: str(p.relative_to(PACKAGE)))
def test_reproducible_layers_take_transcendental_functions_from_stablemath(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in {"np", "numpy"}:
            assert node.attr not in MACHINE_DEPENDENT, (
                f"{path}:{node.lineno}: np.{node.attr} differs between machines; use slamtrials.stablemath "
                "(or write the products out instead of BLAS)")
        if isinstance(node, ast.BinOp):
            assert not isinstance(node.op, ast.MatMult), f"{path}:{node.lineno}: '@' runs BLAS, whose kernels differ by CPU"


#: fast-math flags that let LLVM change results by the CPU it compiles for (vector width, FMA, approximations).
_RESULT_CHANGING_FASTMATH = {"fast", "reassoc", "contract", "afn", "arcp"}


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_numba_kernels_use_no_result_changing_fast_math(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.keyword) and node.arg == "fastmath":
            flags = ast.literal_eval(node.value)
            assert flags is not True, f"{path}:{node.value.lineno}: fastmath=True reassociates and contracts"
            if isinstance(flags, (set, frozenset, list, tuple)):
                assert not set(flags) & _RESULT_CHANGING_FASTMATH, (
                    f"{path}:{node.value.lineno}: fastmath {sorted(set(flags) & _RESULT_CHANGING_FASTMATH)} "
                    "changes results with the CPU")
