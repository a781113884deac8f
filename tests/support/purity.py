"""Checks that a package stays free of others: what its sources import, and what importing it loads.

The engine and the gateway both promise this (no Django; the gateway nothing of hrc either),
so their tests share one way to look.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from collections.abc import Collection
from pathlib import Path


def forbidden_imports(package: Path, forbidden: Collection[str]) -> list[str]:
    """`file: module` for every import statement in the package naming a forbidden top package."""
    offenders = []
    for path in sorted(package.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            offenders += [
                f"{path.relative_to(package)}: {name}"
                for name in names
                if name.split(".")[0] in forbidden
            ]
    return offenders


def package_modules(package: Path, root: Path) -> list[str]:
    """The dotted name, seen from the import root `root`, of every module of the package; its
    `__init__` and `__main__` left out."""
    return [
        ".".join(path.relative_to(root).with_suffix("").parts)
        for path in sorted(package.rglob("*.py"))
        if path.stem not in {"__init__", "__main__"}
    ]


def loaded_by_importing(modules: list[str], cwd: Path, forbidden: Collection[str]) -> list[str]:
    """The forbidden top packages a fresh interpreter has loaded once it imported `modules`."""
    script = (
        f"import sys, {', '.join(modules)}; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & "
        f"set({sorted(forbidden)!r})))"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True, cwd=cwd
    )
    return ast.literal_eval(result.stdout.strip())  # type: ignore[no-any-return]
