"""Long-running processes freeze what they loaded at start-up (hrc/process.py)."""

import subprocess
import sys

from django.conf import settings

# Django, DRF, Channels and hrc's modules: far more than this once loaded.
LOADED_AT_START_UP = 50_000


def _frozen_after(statement: str) -> int:
    script = f"import gc\n{statement}\nprint(gc.get_freeze_count())"
    environment = {"DJANGO_SETTINGS_MODULE": "hrc.settings.test", "PATH": "/usr/bin:/bin"}
    output = subprocess.run(
        [sys.executable, "-c", script],
        cwd=settings.BASE_DIR, env=environment, capture_output=True, text=True, check=True,
    )  # fmt: skip
    return int(output.stdout.split()[-1])


def test_the_web_process_freezes_what_it_loaded() -> None:
    assert _frozen_after("import hrc.asgi") > LOADED_AT_START_UP


def test_a_worker_freezes_what_it_loaded() -> None:
    statement = "import django; django.setup(); import hrc.celery; hrc.celery._freeze_start_up()"
    assert _frozen_after(statement) > LOADED_AT_START_UP


def test_nothing_is_frozen_by_merely_setting_django_up() -> None:
    # The count above comes from the freeze, not from the interpreter.
    assert _frozen_after("import django; django.setup()") == 0
