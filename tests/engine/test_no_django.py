"""The engine is pure Python: no module under hrc/engine imports Django, directly or through others."""

import ast
import subprocess
import sys
from pathlib import Path

ENGINE = Path(__file__).resolve().parents[2] / "hrc" / "engine"


def test_no_engine_module_names_django_in_an_import() -> None:
    offenders = []
    for path in sorted(ENGINE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            offenders += [
                f"{path.name}: {n}"
                for n in names
                if n.split(".")[0] in {"django", "rest_framework", "channels", "celery"}
            ]

    assert offenders == []


def test_importing_the_whole_engine_loads_no_django() -> None:
    modules = ", ".join(
        f"hrc.engine.{p.stem}" for p in sorted(ENGINE.glob("*.py")) if p.stem != "__init__"
    )
    script = f"import sys, {modules}; print(sorted(m for m in sys.modules if m.split('.')[0] == 'django'))"

    result = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        check=True,
        cwd=ENGINE.parents[1],
    )

    assert result.stdout.strip() == "[]"
