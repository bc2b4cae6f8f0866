"""The import rules of docs/architecture.md, kept by scanning the source (relative imports too).

- The floor (config, geometry, messages, camera model) imports nothing else of the project.
- The simulator never imports vision, strategy or the brain: it must not know how the team sees or
  thinks.
- No stage package (vision, sim, strategy and the algorithm packages under cmdragons/) imports the
  composition: the runtime, the team's brain, the benchmarks or the command line.
- Heavy I/O libraries stay in the packages that own them: zenoh and protobuf in the runtime, pymunk in sim/,
  mcap in the runtime's log, PyAV in the video module, OpenCV's video files in the modules that read
  or write recordings and videos.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FLOOR = {"cmdragons.config", "cmdragons.geometry", "cmdragons.messages", "cmdragons.camera", "cmdragons.recording",
         "cmdragons.videoio", "cmdragons._kernels", "cmdragons.sorting", "cmdragons.angles"}
PROJECT = ("cmdragons", "vision", "strategy", "sim")
COMPOSITION = ("cmdragons.runtime", "cmdragons.team", "cmdragons.bench", "cmdragons.cli")
# library -> the module prefixes allowed to import it
OWNERS: dict[str, tuple[str, ...]] = {
    "zenoh": ("cmdragons.runtime",),
    "pymunk": ("sim",),
    "mcap": ("cmdragons.runtime",),
    "mcap_protobuf": ("cmdragons.runtime",),
    "google": ("cmdragons.runtime",),  # protobuf
    "foxglove_schemas_protobuf": ("cmdragons.runtime",),
    "av": ("cmdragons.videoio",),
    "matplotlib": ("cmdragons.runtime", "cmdragons.bench"),
}
CV2_VIDEO = ("VideoWriter", "VideoCapture")
CV2_VIDEO_OWNERS = ("cmdragons.videoio", "cmdragons.recording", "vision.sources", "cmdragons.cli",
                    "cmdragons.runtime", "cmdragons.bench")


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imports(path: Path) -> set[str]:
    """Every module ``path`` imports, relative imports resolved against its package."""
    return imports_of(path.read_text(encoding="utf-8"), module_name(path), path.name == "__init__.py")


def imports_of(source: str, module: str, is_package: bool) -> set[str]:
    tree = ast.parse(source)
    package = module.split(".") if is_package else module.split(".")[:-1]
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                base = node.module or ""
            else:
                base = ".".join(package[: len(package) - node.level + 1] + ([node.module] if node.module else []))
            out.add(base)
            out |= {f"{base}.{a.name}" for a in node.names}  # `from pkg import module`
    return out


def sources(*packages: str) -> list[Path]:
    return sorted(p for pkg in packages for p in (ROOT / pkg.replace(".", "/")).rglob("*.py"))


def under(module: str, prefixes: tuple[str, ...]) -> bool:
    return any(module == p or module.startswith(p + ".") for p in prefixes)


def project_imports(path: Path) -> set[str]:
    return {m for m in imports(path) if m.split(".")[0] in PROJECT}


ALL = sources(*PROJECT)
STAGE_PACKAGES = [p for p in ALL if not under(module_name(p), COMPOSITION)]


def test_relative_imports_are_resolved() -> None:
    found = imports_of("from ..runtime import bus\nfrom . import world\n", "cmdragons.planning.errt", False)
    assert {"cmdragons.runtime", "cmdragons.runtime.bus", "cmdragons.planning.world"} <= found
    found = imports_of("from .errt import ERRTPlanner\n", "cmdragons.planning", True)
    assert "cmdragons.planning.errt" in found


@pytest.mark.parametrize("module", sorted(FLOOR))
def test_floor_imports_only_the_floor(module: str) -> None:
    path = ROOT / (module.replace(".", "/") + ".py")
    assert {m for m in project_imports(path) if not under(m, tuple(FLOOR))} == set(), path


@pytest.mark.parametrize("path", sources("sim"), ids=lambda p: p.name)
def test_sim_never_imports_vision_strategy_or_the_brain(path: Path) -> None:
    bad = {m for m in project_imports(path) if not (under(m, tuple(FLOOR)) or m.split(".")[0] == "sim")}
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize("path", STAGE_PACKAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_stage_packages_do_not_import_the_composition(path: Path) -> None:
    bad = {m for m in project_imports(path) if under(m, COMPOSITION)}
    assert not bad, f"{path} imports {bad}"


@pytest.mark.parametrize("path", ALL, ids=lambda p: str(p.relative_to(ROOT)))
def test_heavy_io_libraries_stay_with_their_owners(path: Path) -> None:
    module = module_name(path)
    bad = {m for m in imports(path) if m.split(".")[0] in OWNERS and not under(module, OWNERS[m.split(".")[0]])}
    assert not bad, f"{path} imports {bad}"
    if not under(module, CV2_VIDEO_OWNERS):
        text = path.read_text(encoding="utf-8")
        assert not any(f"cv2.{name}" in text for name in CV2_VIDEO), f"{path} opens video files with OpenCV"


# --- private modules, planning below navigation, import cycles ----------------------------------------------
def package_of(module: str, path: Path) -> str:
    return module if path.name == "__init__.py" else module.rpartition(".")[0]


def private_owner(module: str) -> str | None:
    """The package a private module (``pkg._kernels``, ``pkg._reference`` ...) belongs to, or None."""
    parts = module.split(".")
    for i, part in enumerate(parts):
        if part.startswith("_") and not part.startswith("__"):
            return ".".join(parts[:i])
    return None


def test_private_owner() -> None:
    assert private_owner("cmdragons.planning._errt_kernels") == "cmdragons.planning"
    assert private_owner("cmdragons.planning._errt_kernels.errt_grow") == "cmdragons.planning"
    assert private_owner("cmdragons.planning.collision.away") is None


@pytest.mark.parametrize("path", STAGE_PACKAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_stage_package_imports_another_packages_private_module(path: Path) -> None:
    """A kernel two packages share lives in a public module of the lower one; a package's private
    modules (its kernels, their references) are its own and its subpackages'. (The composition's
    warm-up and benchmarks compile and time kernels by name, so they may reach them.)"""
    module = module_name(path)
    package = package_of(module, path)
    bad = set()
    for m in project_imports(path):
        owner = private_owner(m)
        if owner is not None and not under(package, (owner,)):
            bad.add(m)
    assert not bad, f"{path} imports another package's private modules: {sorted(bad)}"


@pytest.mark.parametrize("path", sources("cmdragons.planning"), ids=lambda p: str(p.relative_to(ROOT)))
def test_planning_never_imports_navigation(path: Path) -> None:
    bad = {m for m in project_imports(path) if under(m, ("cmdragons.navigation",))}
    assert not bad, f"{path} imports {bad}"


def module_graph() -> dict[str, set[str]]:
    """Module -> the project modules it imports (a ``from pkg import name`` counts as an import of
    ``pkg.name`` when that is a module, else of ``pkg``), over every module of the project, the
    imports inside functions and under TYPE_CHECKING included: a cycle there is still a knot."""
    modules = {module_name(p): p for p in ALL}
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        targets = set()
        for m in project_imports(path):
            while m and m not in modules:
                m = m.rpartition(".")[0]
            if m and m != name:
                targets.add(m)
        graph[name] = targets
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted; a package's
    ``__init__`` importing its own modules is not a cycle by itself, so edges from a module to a
    package that contains it are left out."""
    edges = {a: {b for b in bs if not a.startswith(b + ".")} for a, bs in graph.items()}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:  # recursion depth is bounded by the number of modules (a few hundred)
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return sorted(out)


def test_the_cycle_finder_finds_a_cycle_and_ignores_a_package_importing_its_modules() -> None:
    graph = {"a": {"a.x"}, "a.x": {"b"}, "b": {"a.x"}, "c": {"c.y"}, "c.y": {"c"}}
    assert cycles(graph) == [["a.x", "b"]]


def test_no_import_cycles() -> None:
    found = cycles(module_graph())
    assert not found, "import cycles: " + "; ".join(" <-> ".join(c) for c in found)
