"""The package's layers (docs/architecture.md): imports run one way, down the user's path.

Read from the source with the ast module, nothing imported: every ``import`` of a dynid module
(at module level or inside a function; type-only imports under ``if TYPE_CHECKING:`` aside,
since they never run) must name a module of the same subpackage or of a lower layer. A new import
that runs back up fails here with its file and line.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "python" / "dynid"

#: The layers, lowest first (docs/architecture.md). A top-level part (a module or a subpackage)
#: may import its own subpackage and the parts of lower layers only; parts of one layer are peers
#: that never import each other (a simulation needs no log reader, a log reader no trajectory).
LAYERS: list[set[str]] = [
    {"_core", "_checks", "_equality", "_threads", "_version", "errors", "cmake"},
    {"model"},
    {"excitation", "motion", "sim", "logs"},
    {"identification"},
    {"export"},
    {"cli"},
    {"__init__", "__main__", "io"},  # the facades: the public names, re-exported; python -m dynid
]
#: The layers whose parts may import each other: the foundation (the checks use the C++ core)
#: and the facades.
OPEN_LAYERS = {0, len(LAYERS) - 1}
RANK = {part: rank for rank, parts in enumerate(LAYERS) for part in parts}
MAX_TOP_LEVEL_MODULES = 12


def _module_name(path: Path) -> tuple[list[str], bool]:
    parts = list(path.relative_to(PACKAGE).with_suffix("").parts)
    is_package = parts[-1] == "__init__"
    return (parts[:-1] if is_package else parts), is_package


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _runtime_imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    found: list[ast.Import | ast.ImportFrom] = []

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            found.append(node)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def _targets(
    node: ast.Import | ast.ImportFrom, here: list[str], is_package: bool
) -> list[list[str]]:
    """The dynid modules (as name parts below dynid) that an import statement loads."""
    if isinstance(node, ast.Import):
        return [a.name.split(".")[1:] for a in node.names if a.name.split(".")[0] == "dynid"]
    if node.level == 0:
        if not node.module or node.module.split(".")[0] != "dynid":
            return []
        base = node.module.split(".")[1:]
    else:
        package = here if is_package else here[:-1]
        base = package[: len(package) - (node.level - 1)] + (
            node.module.split(".") if node.module else []
        )
    # `from . import x` names a module x when it is one; otherwise a name of the module `base`
    targets = []
    for alias in node.names:
        candidate = PACKAGE.joinpath(*base, alias.name)
        if candidate.with_suffix(".py").exists() or (candidate / "__init__.py").exists():
            targets.append([*base, alias.name])
        elif base == [] and alias.name == "_core":
            targets.append(["_core"])
        else:
            targets.append(base)
    return targets


def _sources() -> list[tuple[Path, str]]:
    return [(path, path.read_text(encoding="utf-8")) for path in sorted(PACKAGE.rglob("*.py"))]


def _violations(sources: list[tuple[Path, str]]) -> list[str]:
    found = []
    for path, text in sources:
        here, is_package = _module_name(path)
        source_part = here[0] if here else "__init__"
        for node in _runtime_imports(ast.parse(text)):
            for target in _targets(node, here, is_package):
                target_part = target[0] if target else "__init__"
                if target_part == source_part:
                    continue
                where = f"{path.relative_to(PACKAGE.parent)}:{node.lineno}"
                if target_part not in RANK or source_part not in RANK:
                    found.append(f"{where}: {source_part} or {target_part} is in no layer")
                elif RANK[target_part] > RANK[source_part] or (
                    RANK[target_part] == RANK[source_part] and RANK[source_part] not in OPEN_LAYERS
                ):
                    found.append(
                        f"{where}: {source_part} (layer {RANK[source_part]}) imports "
                        f"dynid.{'.'.join(target)} (layer {RANK[target_part]})"
                    )
    return found


def test_every_top_level_part_is_in_a_layer() -> None:
    parts = {p.stem for p in PACKAGE.glob("*.py")} | {
        p.parent.name for p in PACKAGE.glob("*/__init__.py")
    }
    assert parts - set(RANK) == set()


def test_imports_never_run_back_up_the_layers() -> None:
    assert _violations(_sources()) == []


def test_at_most_twelve_modules_at_the_top_level() -> None:
    assert len(list(PACKAGE.glob("*.py"))) <= MAX_TOP_LEVEL_MODULES


@pytest.mark.parametrize(
    "source",
    [
        "from ..identification.identify import least_squares\n",  # a layer up
        "from ..sim import simulate\n",  # a peer
        "def f():\n    from ..export import plots\n",  # inside a function
        "import dynid.cli\n",
    ],
)
def test_the_check_sees_an_import_that_runs_back_up(source: str) -> None:
    # The same rule applied to a module of logs/ (not written to disk): each is reported.
    assert len(_violations([(PACKAGE / "logs" / "_layer_probe.py", source)])) == 1


def test_a_type_only_import_is_not_a_runtime_dependency() -> None:
    tree = ast.parse(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from ..cli import main\n"
    )
    assert [type(n).__name__ for n in _runtime_imports(tree)] == ["ImportFrom"]
