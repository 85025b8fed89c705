"""The layers of docs/architecture.md hold: imports point down, no cycle, small modules."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "articula"
# Layer of each top-level package or module, in the order of docs/architecture.md; a module
# imports only lower layers and its own package.
LAYERS = {
    "errors": 0,
    "limits": 0,
    "signals": 0,
    "native": 0,
    "disk_cache": 0,
    "numba_cache": 1,
    "validation": 1,
    "__init__": 1,
    "geometry": 2,
    "plants": 2,
    "robots": 3,
    "scene": 4,
    "control": 5,
    "tuning": 6,
    "planning": 7,
    "loops": 8,
    "runs": 9,
    "sim": 9,
    "rigs": 10,
    "arms": 10,
    "identify": 10,
    "experiments": 11,
    "book": 12,
    "bench": 12,
    "viewer": 12,
    "cli": 13,
    "__main__": 14,
}
MAX_LINES = 400


def _modules() -> Iterator[tuple[str, Path]]:
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(SRC).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield ".".join(parts), path


def _imports(path: Path, top_level_only: bool) -> set[str]:
    """articula modules that `path` imports (all of them, or only at module level)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    found = set()
    for node in nodes:
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        found |= {n for n in names if n == "articula" or n.startswith("articula.")}
    return found


def _layer(module: str) -> tuple[str, int]:
    parts = module.split(".")
    top = parts[1] if len(parts) > 1 else "__init__"
    return top, LAYERS[top]


MODULES = dict(_modules())


@pytest.mark.parametrize("module", sorted(MODULES))
def test_a_module_imports_only_lower_layers_and_its_own_package(module):
    top, layer = _layer(module)
    for target in _imports(MODULES[module], top_level_only=False):
        if target not in MODULES:
            continue  # a name inside a module (from x import name), checked through x
        other, other_layer = _layer(target)
        assert other == top or other_layer < layer, f"{module} imports {target}"


def test_only_the_cli_and_the_book_itself_import_the_chapter_homes():
    for module, path in MODULES.items():
        if module.startswith(("articula.book", "articula.cli")):
            continue
        book = {t for t in _imports(path, top_level_only=False) if t.startswith("articula.book")}
        assert not book, f"{module} imports {sorted(book)}"


def test_there_is_no_import_cycle_among_modules():
    graph = {m: {t for t in _imports(p, top_level_only=True) if t in MODULES and t != m}
             for m, p in MODULES.items()}  # fmt: skip
    done: set[str] = set()

    def visit(node: str, path: list[str]) -> None:
        if node in path:
            cycle = [*path[path.index(node) :], node]
            raise AssertionError("import cycle: " + " -> ".join(cycle))
        if node in done:
            return
        for target in graph[node]:
            visit(target, [*path, node])
        done.add(node)

    for module in graph:
        visit(module, [])


def test_every_top_level_package_has_a_layer():
    tops = {_layer(m)[0] for m in MODULES}
    assert tops <= set(LAYERS)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_source_module_is_over_the_line_limit(module):
    lines = MODULES[module].read_text(encoding="utf-8").count("\n")
    assert lines <= MAX_LINES, f"{module}: {lines} lines"


MAX_CLI_LINES = 150  # the CLI parses, calls and prints; the work lives below it


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("articula.cli")))
def test_no_cli_module_is_over_its_line_limit(module):
    lines = MODULES[module].read_text(encoding="utf-8").count("\n")
    assert lines <= MAX_CLI_LINES, f"{module}: {lines} lines; move the work below the CLI"


# A plan is assembled once, by articula.experiments.plan.build_plan: a scene built from a
# config together with a planner or an online controller made for it. Any other module (or
# benchmark or example) that does both is a second assembly, which would drift from the first
# (its errors naming other keys, its defaults other values).
BUILDERS = {"build_scene", "load_scene_spec"}
PLANNERS = {"make_planner", "from_spec"}
ASSEMBLY = "articula.experiments.plan"
ROOT = SRC.parent


def _called(path: Path) -> set[str]:
    """Names of the functions and methods `path` calls."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call):
            func = node.func
            names.add(func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", ""))
    return names


def _scripts() -> Iterator[tuple[str, Path]]:
    """Every module of articula, every benchmark and every example."""
    yield from MODULES.items()
    for folder in ("benchmarks", "examples"):
        for path in sorted((ROOT / folder).glob("*.py")):
            yield f"{folder}/{path.name}", path


@pytest.mark.parametrize(("name", "path"), list(_scripts()), ids=lambda v: str(v))
def test_a_plan_is_assembled_only_by_build_plan(name, path):
    calls = _called(path)
    if name != ASSEMBLY and calls & BUILDERS:
        assert not calls & PLANNERS, f"{name} builds a scene and a planner: use build_plan"


def test_the_assembly_check_finds_a_second_assembly(tmp_path):
    second = tmp_path / "second.py"
    second.write_text(
        "scene, q0 = build_scene(load_scene_spec(data), folder)\n"
        "controller = OnlineController.from_spec(scene, spec)\n"
    )
    assert _called(second) & BUILDERS and _called(second) & PLANNERS


@pytest.mark.parametrize(
    "package",
    sorted(m for m, p in MODULES.items() if p.name == "__init__.py" and m.count(".") == 1),
)
def test_every_public_subpackage_declares_its_public_modules(package):
    init = MODULES[package]
    if package in ("articula.book", "articula.cli"):  # the application, not the library's API
        return
    tree = ast.parse(init.read_text())
    declared = next(
        (ast.literal_eval(node.value) for node in tree.body if isinstance(node, ast.Assign)
         and any(getattr(t, "id", "") == "__all__" for t in node.targets)),
        None,
    )  # fmt: skip
    assert declared, f"{package} has no __all__"
    modules = {p.stem for p in init.parent.glob("*.py") if not p.stem.startswith("_")}
    bound = {alias.asname or alias.name for node in tree.body if isinstance(node, ast.ImportFrom)
             for alias in node.names}  # fmt: skip
    assert set(declared) <= modules | bound, f"{package}.__all__ names what it does not hold"


def test_the_formatter_is_trusted():
    """`# fmt: skip` only where a table would be unreadable (issue 28: at most 50 in src)."""
    count = sum(path.read_text().count("# fmt: skip") for path in MODULES.values())
    assert count <= 50
