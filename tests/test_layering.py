"""The packages' layering, checked on the source: ``capt_common`` needs none of the others,
``perception`` needs neither ``capt_env`` nor ``agents``, and ``capt_env`` reaches ``agents`` only from
its CLI verbs (``capt_env/commands``), lazily inside functions, so that the envs and ``capt --help``
never import a policy."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _imports(path: Path) -> list[tuple[str, int, bool]]:
    """(imported top-level package, line, at module level) of every import in ``path``; imports under
    ``if TYPE_CHECKING:`` are skipped (they never run)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found: list[tuple[str, int, bool]] = []

    def visit(node: ast.AST, top: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                for orelse in child.orelse:
                    visit(ast.Module(body=[orelse], type_ignores=[]), top)
                continue
            if isinstance(child, ast.Import):
                found.extend((a.name.split(".")[0], child.lineno, top) for a in child.names)
            elif isinstance(child, ast.ImportFrom) and child.level == 0 and child.module:
                found.append((child.module.split(".")[0], child.lineno, top))
            inner = top and not isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            visit(child, inner)

    visit(tree, True)
    return found


def _violations(package: str, forbidden: set[str], only_top_level: bool = False,
                skip: str | None = None) -> list[str]:
    bad = []
    for path in sorted((ROOT / package).rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        if skip and rel.startswith(skip):
            continue
        for name, line, top in _imports(path):
            if name in forbidden and (top or not only_top_level):
                bad.append(f"{rel}:{line} imports {name}")
    return bad


@pytest.mark.parametrize(("package", "forbidden"), [
    ("capt_common", {"capt_env", "perception", "agents"}),
    ("perception", {"capt_env", "agents"}),
])
def test_lower_packages_import_no_higher_one(package: str, forbidden: set[str]) -> None:
    assert _violations(package, forbidden) == []


def test_capt_env_reaches_agents_only_from_cli_verbs_and_lazily() -> None:
    assert _violations("capt_env", {"agents"}, skip="capt_env/commands/") == []
    assert _violations("capt_env/commands", {"agents"}, only_top_level=True) == []


def test_the_checker_sees_imports(tmp_path: Path) -> None:
    src = tmp_path / "m.py"
    src.write_text("import agents.ppo\nfrom typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                   "    from agents import x\n"
                   "def f():\n    from agents.scripted import rollout\nclass C:\n    import capt_env\n")
    assert _imports(src) == [("agents", 1, True), ("typing", 2, True), ("agents", 6, False),
                             ("capt_env", 8, True)]
