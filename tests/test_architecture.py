"""The layer rule of DESIGN.md and the library-wide conventions, checked on the source tree."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "slamtrials"

#: Modules every layer may import: they hold no behaviour of any layer (``cost`` and ``costmeter``: what a
#: run cost in CPU time and memory, and the meter that reads the clocks and the kernel's counters).
UTILITIES = {"errors", "atomicfile", "__about__", "stablemath", "seeding", "compilewatch", "cost", "costmeter"}

#: Layer -> the slamtrials layers it may import (DESIGN.md, "Layers").
ALLOWED = {
    "geometry": set(),
    "record": {"geometry"},
    "worlds": {"geometry"},
    "sim": {"geometry", "record", "worlds"},
    "slam": {"geometry", "record"},
    "explore": {"geometry", "record"},
    "trial": {"geometry", "record", "worlds", "sim", "slam", "explore"},
    # validation composes sim, slam and metric like a trial (DESIGN.md, "Realism"), and calibration for the
    # split-half check (fit on one half of a log, validate on the other); it computes only
    # and external for a program under validation (the one place it starts a process)
    "validation": {"geometry", "record", "worlds", "sim", "slam", "metric", "calibration", "external"},
    "metric": {"geometry", "record"},
    "calibration": {"geometry", "record", "worlds", "sim", "slam", "metric"},
    "io": {"geometry", "record", "worlds"},
    # external runs SLAM programs: writes their input and reads their output through io, starts processes
    "external": {"geometry", "record", "worlds", "slam", "io"},
    "campaign": {"geometry", "record", "worlds", "sim", "slam", "explore", "trial", "metric", "io", "external"},
    "report": {"geometry", "record", "worlds", "metric", "io", "campaign", "calibration"},
    # a study: campaigns over a grid of settings (run through campaign), its page through report
    "study": {"geometry", "record", "worlds", "sim", "slam", "explore", "trial", "metric", "io", "campaign", "report"},
}
#: Top-level modules that compose layers like the CLI does (no layer may import them).
COMPOSERS = {"demo", "evaluation", "slamrun", "repeat", "cli", "__init__", "__main__"}

#: Layers that must not do I/O, print or plot (DESIGN.md).
COMPUTING = {"geometry", "record", "sim", "slam", "explore", "trial", "metric", "validation", "calibration"}

#: numpy functions whose float64 results depend on the machine: numpy's own SIMD code for these on
#: AVX-512 CPUs differs from the C library's by a few ulp, and BLAS picks its kernels by CPU.
MACHINE_DEPENDENT = {
    "sin",
    "cos",
    "tan",
    "arcsin",
    "arccos",
    "arctan",
    "arctan2",
    "hypot",
    "sinh",
    "cosh",
    "tanh",
    "arcsinh",
    "arccosh",
    "arctanh",
    "exp",
    "exp2",
    "expm1",
    "log",
    "log2",
    "log10",
    "log1p",
    "power",
    "float_power",
    "cbrt",
    "dot",
    "vdot",
    "inner",
    "matmul",
    "tensordot",
    "einsum",
    "linalg",
}
#: Layers whose numbers end up in runs, maps and files, and must be the same on every machine.
REPRODUCIBLE = COMPUTING | {"worlds", "io", "external", "campaign"}


def _layer_of(path: Path) -> str:
    relative = path.relative_to(PACKAGE)
    return relative.parts[0].removesuffix(".py")


def _imported_layers(tree: ast.AST) -> set[str]:
    layers = set()
    for node in _nodes(tree):
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


@functools.cache
def _tree(path: Path) -> ast.Module:
    """The module's syntax tree, parsed once for all the checks below (none changes it)."""
    return ast.parse(path.read_text(encoding="utf-8"))


@functools.cache
def _nodes(tree: ast.AST) -> tuple[ast.AST, ...]:
    """Every node of ``tree`` (``ast.walk``'s order), listed once for all the checks that walk it."""
    return tuple(ast.walk(tree))


@pytest.fixture(scope="module", autouse=True)
def _forget_the_trees():
    """Let the trees go after this module: a million nodes kept alive slow every later garbage collection."""
    yield
    _tree.cache_clear()
    _nodes.cache_clear()


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_layer_imports_only_layers_above_it(path: Path) -> None:
    layer = _layer_of(path)
    if layer in COMPOSERS:
        return
    assert layer in ALLOWED or layer in UTILITIES, f"{path}: module outside the layers of DESIGN.md"
    allowed = ALLOWED.get(layer, set()) | UTILITIES | {layer}
    imported = _imported_layers(_tree(path))
    assert imported <= allowed, f"{path}: layer '{layer}' imports {sorted(imported - allowed)}"


@pytest.mark.parametrize(
    "path", [p for p in SOURCES if _layer_of(p) != "cli"], ids=lambda p: str(p.relative_to(PACKAGE))
)
def test_library_code_never_prints_exits_or_uses_global_random_state(path: Path) -> None:
    tree = _tree(path)
    for node in _nodes(tree):
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


@pytest.mark.parametrize(
    "path", [p for p in SOURCES if _layer_of(p) in COMPUTING], ids=lambda p: str(p.relative_to(PACKAGE))
)
def test_computing_layers_do_no_file_io_or_plotting(path: Path) -> None:
    tree = _tree(path)
    for node in _nodes(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            assert node.func.id != "open", f"{path}:{node.lineno}: opens a file"
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            module = node.module if isinstance(node, ast.ImportFrom) else node.names[0].name
            assert not (module or "").startswith(("matplotlib", "PIL")), f"{path}:{node.lineno}: imports {module}"


@pytest.mark.parametrize(
    "path", [p for p in SOURCES if _layer_of(p) in REPRODUCIBLE], ids=lambda p: str(p.relative_to(PACKAGE))
)
def test_reproducible_layers_take_transcendental_functions_from_stablemath(path: Path) -> None:
    tree = _tree(path)
    for node in _nodes(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in {"np", "numpy"}:
            assert node.attr not in MACHINE_DEPENDENT, (
                f"{path}:{node.lineno}: np.{node.attr} differs between machines; use slamtrials.stablemath "
                "(or write the products out instead of BLAS)"
            )
        if isinstance(node, ast.BinOp):
            assert not isinstance(node.op, ast.MatMult), (
                f"{path}:{node.lineno}: '@' runs BLAS, whose kernels differ by CPU"
            )
        assert not machine_dependent_power(node), (
            f"{path}:{node.lineno}: '{ast.unparse(node)}': '**' on a numpy array is numpy's power, whose "
            "AVX-512 code differs from the C library's; use slamtrials.stablemath.power"
        )


def machine_dependent_power(node: ast.AST) -> bool:
    """Whether ``node`` is ``a ** b`` with an exponent other than a whole number or 0.5. The source does not
    say whether ``a`` is an array. On an array numpy computes 2, 1, 0, -1 and 0.5 exactly (a square, a copy,
    a reciprocal, a square root) and every other exponent with a ``pow`` whose AVX-512 code differs; on a
    float, Python's and numba's ``**`` are the C library's. A fractional exponent is flagged wherever it
    is (a float in one place is an array in another); other whole ones are let through, as the
    codebase's few (``2 ** 63``, karto's cube of a scalar quality) are on scalars."""
    if not (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow)):
        return False
    exponent = node.right
    if isinstance(exponent, ast.UnaryOp) and isinstance(exponent.op, ast.USub):
        exponent = exponent.operand
    return not (isinstance(exponent, ast.Constant) and (isinstance(exponent.value, int) or exponent.value == 0.5))


@pytest.mark.parametrize(
    ("source", "flagged"),
    [
        ("low * (high / low) ** a", True),
        ("x ** 1.5", True),
        ("x ** -0.7", True),
        ("x ** 2", False),
        ("x ** -1", False),
        ("x ** 0.5", False),
        ("np.hypot(x, y)", False),
    ],
)
def test_power_guard_flags_exponents_numpy_computes_with_pow(source: str, flagged: bool) -> None:
    assert any(machine_dependent_power(node) for node in ast.walk(ast.parse(source))) == flagged


#: fast-math flags that let LLVM change results by the CPU it compiles for (vector width, FMA, approximations).
_RESULT_CHANGING_FASTMATH = {"fast", "reassoc", "contract", "afn", "arcp"}


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_numba_kernels_use_no_result_changing_fast_math(path: Path) -> None:
    tree = _tree(path)
    for node in _nodes(tree):
        if isinstance(node, ast.keyword) and node.arg == "fastmath":
            flags = ast.literal_eval(node.value)
            assert flags is not True, f"{path}:{node.value.lineno}: fastmath=True reassociates and contracts"
            if isinstance(flags, (set, frozenset, list, tuple)):
                assert not set(flags) & _RESULT_CHANGING_FASTMATH, (
                    f"{path}:{node.value.lineno}: fastmath {sorted(set(flags) & _RESULT_CHANGING_FASTMATH)} "
                    "changes results with the CPU"
                )


#: Sort kinds whose order of equal keys is fixed. numpy's default (quicksort) is not stable, and its SIMD
#: versions (x86-simd-sort, picked by CPU) order equal keys differently: on AVX-512 CPUs the generator once
#: put a world's start pose 0.2 m away from where an AVX2 machine put it.
_STABLE_KINDS = {"stable", "mergesort"}


def _is_set_expression(node: ast.AST) -> bool:
    """``set(...)``, ``frozenset(...)``, a set literal or comprehension, or a union/difference/... of them."""
    if isinstance(node, (ast.Set, ast.SetComp)):
        return True
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in {"set", "frozenset"}:
        return True
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.BitOr, ast.BitAnd, ast.Sub, ast.BitXor)):
        return _is_set_expression(node.left) or _is_set_expression(node.right)
    return False


def ordering_problems(tree: ast.AST) -> list[str]:
    """Sorts whose order of ties depends on the implementation, and iterations over sets, as ``line: what``.

    * ``np.sort``/``np.argsort`` and the ``.sort()``/``.argsort()``/``.sort_values()`` methods need
      ``kind="stable"`` (or ``"mergesort"``); a ``.sort()`` with ``key=`` or ``reverse=`` is Python's
      list sort, which is stable. ``np.lexsort`` is stable; ``argpartition`` never is.
    * Iterating a set (``for x in set(...)``, in a comprehension, or through ``list``/``tuple``/``join``):
      the order of strings changes with PYTHONHASHSEED; iterate ``sorted(...)`` instead.
    """
    problems = []
    for node in _nodes(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            name = node.func.attr
            keywords = {k.arg: k.value for k in node.keywords}
            kind = keywords.get("kind")
            stable = isinstance(kind, ast.Constant) and kind.value in _STABLE_KINDS
            python_list_sort = name == "sort" and ("key" in keywords or "reverse" in keywords) and kind is None
            if name in {"sort", "argsort", "sort_values"} and not stable and not python_list_sort:
                problems.append(
                    f'{node.lineno}: {ast.unparse(node.func)}() without kind="stable" orders equal keys by '
                    "implementation (numpy's SIMD sorts differ by CPU)"
                )
            if name == "argpartition":
                problems.append(
                    f"{node.lineno}: argpartition orders equal keys by implementation; use a stable argsort"
                )
        iterated = []
        if isinstance(node, (ast.For, ast.comprehension)):
            iterated.append(node.iter)
        if (
            isinstance(node, ast.Call)
            and node.args
            and (
                (isinstance(node.func, ast.Name) and node.func.id in {"list", "tuple", "enumerate"})
                or (isinstance(node.func, ast.Attribute) and node.func.attr == "join")
            )
        ):
            iterated.append(node.args[0])
        problems += [
            f"{it.lineno}: iterates a set, whose order of strings depends on PYTHONHASHSEED; iterate sorted(...)"
            for it in iterated
            if _is_set_expression(it)
        ]
    return problems


#: Layers whose order of things reaches runs, maps, worlds or files: the reproducible ones and the report.
ORDERED = REPRODUCIBLE | {"report"}


@pytest.mark.parametrize(
    "path", [p for p in SOURCES if _layer_of(p) in ORDERED], ids=lambda p: str(p.relative_to(PACKAGE))
)
def test_reproducible_layers_order_ties_by_rule_not_by_sort_implementation(path: Path) -> None:
    problems = ordering_problems(_tree(path))
    assert not problems, f"{path}:" + f"\n{path}:".join(problems)


@pytest.mark.parametrize(
    ("source", "flagged"),
    [
        ("np.argsort(d)[0]", True),
        ("np.sort(values)", True),
        ("a.argsort()", True),
        ("a.sort()", True),
        ("np.argsort(d, kind='quicksort')", True),
        ("table.sort_values('x', ascending=False)", True),
        ("np.argpartition(d, 3)", True),
        ("for host in set(a) | set(b):\n    pass", True),
        ("names = [n for n in {'a', 'b'}]", True),
        ("text = ', '.join(set(names))", True),
        ("np.argsort(d, kind='stable')[0]", False),
        ("a.sort(kind='mergesort')", False),
        ("table.sort_values('x', kind='stable')", False),
        ("np.lexsort((fine, coarse))[0]", False),
        ("items.sort(key=len)", False),
        ("for host in sorted(set(a) | set(b)):\n    pass", False),
        ("ok = 'x' in {'a', 'b'}", False),
    ],
)
def test_ordering_guard_flags_unstable_sorts_and_set_iteration(source: str, flagged: bool) -> None:
    assert bool(ordering_problems(ast.parse(source))) == flagged


#: numba's decorators that compile a function (an @intrinsic only emits code inside the kernels that call it).
_NUMBA_COMPILERS = {"njit", "jit", "vectorize", "guvectorize", "cfunc", "generated_jit", "overload", "stencil"}


def _numba_compilers_imported(tree: ast.AST) -> set[str]:
    """The local names of numba's compiling decorators imported with ``from numba... import``."""
    return {
        alias.asname or alias.name
        for node in _nodes(tree)
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "numba"
        for alias in node.names
        if alias.name in _NUMBA_COMPILERS
    }


def _numba_compiler(func: ast.expr, imported: set[str]) -> bool:
    """``njit`` (from numba), ``numba.njit``, ``numba.core.extending.overload``, ...: not ``np.vectorize``
    nor ``typing.overload``."""
    text = ast.unparse(func)
    return text in imported or (text.startswith("numba.") and text.split(".")[-1] in _NUMBA_COMPILERS)


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_numba_kernels_are_module_level_and_cached(path: Path) -> None:
    """A kernel compiles once per install, not once per process: cache=True, and at module level (numba
    cannot cache a closure or a kernel made inside a function, nor one compiled by calling njit(f))."""
    tree = _tree(path)
    imported = _numba_compilers_imported(tree)
    top_level = {id(node) for node in tree.body}
    decorators = {id(d) for node in _nodes(tree) if isinstance(node, ast.FunctionDef) for d in node.decorator_list}
    for node in _nodes(tree):
        if isinstance(node, ast.FunctionDef):
            for decorator in node.decorator_list:
                call = decorator if isinstance(decorator, ast.Call) else None
                if not _numba_compiler(call.func if call else decorator, imported):
                    continue
                assert id(node) in top_level, f"{path}:{node.lineno}: kernel {node.name} is not at module level"
                cached = call is not None and any(
                    k.arg == "cache" and ast.literal_eval(k.value) is True for k in call.keywords
                )
                assert cached, f"{path}:{node.lineno}: kernel {node.name} lacks cache=True"
        elif isinstance(node, ast.Call) and id(node) not in decorators and _numba_compiler(node.func, imported):
            raise AssertionError(f"{path}:{node.lineno}: {ast.unparse(node)} compiles a kernel outside a decorator")
