"""The gateway installs beside a robot without the web application: no Django, nothing of hrc."""

import ast
import subprocess
import sys
from pathlib import Path

GATEWAY = Path(__file__).resolve().parents[2] / "hrc_gateway"
WEB_APPLICATION = {"django", "rest_framework", "channels", "celery", "hrc"}


def test_no_gateway_module_names_django_or_hrc_in_an_import() -> None:
    offenders = []
    for path in sorted(GATEWAY.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            offenders += [
                f"{path.relative_to(GATEWAY)}: {n}"
                for n in names
                if n.split(".")[0] in WEB_APPLICATION
            ]

    assert offenders == []


def test_importing_the_whole_gateway_loads_no_django_and_no_hrc() -> None:
    modules = ", ".join(
        ".".join(path.relative_to(GATEWAY.parent).with_suffix("").parts)
        for path in sorted(GATEWAY.rglob("*.py"))
        if path.stem not in {"__init__", "__main__"}
    )
    script = (
        f"import sys, {modules}; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & "
        f"set({sorted(WEB_APPLICATION)!r})))"
    )

    result = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        check=True,
        cwd=GATEWAY.parent,
    )

    assert "hrc_gateway.ur.rtde_worker" in modules  # the UR backend is imported too
    assert result.stdout.strip() == "[]"
