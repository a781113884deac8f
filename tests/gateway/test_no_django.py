"""The gateway installs beside a robot without the web application: no Django, nothing of hrc."""

from pathlib import Path

from tests.support.purity import forbidden_imports, loaded_by_importing, package_modules

GATEWAY = Path(__file__).resolve().parents[2] / "hrc_gateway"
WEB_APPLICATION = {"django", "rest_framework", "channels", "celery", "hrc"}


def test_no_gateway_module_names_django_or_hrc_in_an_import() -> None:
    assert forbidden_imports(GATEWAY, WEB_APPLICATION) == []


def test_importing_the_whole_gateway_loads_no_django_and_no_hrc() -> None:
    modules = package_modules(GATEWAY, GATEWAY.parent)

    assert "hrc_gateway.ur.rtde_worker" in modules  # the UR backend is imported too
    assert loaded_by_importing(modules, GATEWAY.parent, WEB_APPLICATION) == []
