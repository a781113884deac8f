"""The engine is pure Python: no module under hrc/engine imports Django, directly or through others."""

from pathlib import Path

from tests.support.purity import forbidden_imports, loaded_by_importing, package_modules

ENGINE = Path(__file__).resolve().parents[2] / "hrc" / "engine"
DJANGO = {"django", "rest_framework", "channels", "celery"}


def test_no_engine_module_names_django_in_an_import() -> None:
    assert forbidden_imports(ENGINE, DJANGO) == []


def test_importing_the_whole_engine_loads_no_django() -> None:
    assert (
        loaded_by_importing(package_modules(ENGINE, ENGINE.parents[1]), ENGINE.parents[1], DJANGO)
        == []
    )
