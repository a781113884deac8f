"""Imports point inwards: the layer contracts in pyproject.toml hold, and they do catch an outward arrow.

The contracts are import-linter's (`make lint` runs them too). Here they run on the
tree as it is, then on a copy with one outward import added, which must break them;
and no module under hrc/ hides an import inside a function, the usual way to dodge a cycle.
"""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")
# The packages the contracts cover, as pyproject.toml names them.
PACKAGES = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"][
    "root_packages"
]


def lint_imports(root: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", str(root / "pyproject.toml")],
        cwd=root,
        env={**os.environ, "PYTHONPATH": str(root)},
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


@pytest.fixture
def tree_copy(tmp_path: Path) -> Path:
    """The packages and pyproject.toml, copied without caches, to add an import to."""
    for package in PACKAGES:
        shutil.copytree(
            ROOT / package, tmp_path / package, ignore=shutil.ignore_patterns("__pycache__")
        )
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    return tmp_path


def test_the_layer_contracts_hold() -> None:
    result = lint_imports(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize(
    ("module", "outward", "contract"),
    [
        ("hrc/engine/outward.py", "import django\n", "The engine is pure"),
        ("hrc_gateway/outward.py", "from hrc.cobots import models\n", "The gateway installs alone"),
        ("hrc/cobots/outward.py", "from hrc.cases import models\n", "Apps point inwards"),
        ("hrc/cases/outward.py", "from hrc.live import consumers\n", "Apps point inwards"),
        (
            "hrc/cases/progress_outward.py",
            "from hrc.cases import services\n",
            "The case write path points inwards",
        ),
    ],
)
def test_an_outward_import_breaks_a_contract(
    tree_copy: Path, module: str, outward: str, contract: str
) -> None:
    target = tree_copy / module
    if module.endswith("progress_outward.py"):
        # An arrow from the firing loop back up to the public commands.
        target = tree_copy / "hrc/cases/progress.py"
        target.write_text(target.read_text() + "\n" + outward)
    else:
        target.write_text(outward)
    result = lint_imports(tree_copy)
    assert result.returncode != 0
    assert f"{contract}" in result.stdout
    assert "BROKEN" in result.stdout


def _function_level_imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            for inner in ast.walk(node):
                if isinstance(inner, ast.Import | ast.ImportFrom):
                    found.append(f"{path.relative_to(ROOT)}:{inner.lineno}")
    return found


def test_no_module_imports_inside_a_function() -> None:
    found = [
        where
        for package in PACKAGES
        for path in sorted((ROOT / package).rglob("*.py"))
        for where in _function_level_imports(path)
    ]
    assert found == []
