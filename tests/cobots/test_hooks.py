"""What the cobots app learns from the cases app, and that it never imports it to learn it."""

import ast
from pathlib import Path

import pytest
from django.conf import settings
from django.contrib.auth.models import User

from hrc.cases import jobs
from hrc.cobots import hooks
from hrc.cobots.models import Cobot
from hrc.organisations.models import Organisation
from tests import factories

COBOTS = Path(settings.BASE_DIR) / "hrc" / "cobots"
# The layers above cobots (README: imports point inwards).
HIGHER = ("hrc.cases", "hrc.live", "hrc.analytics", "hrc.patterns", "hrc.demo")


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return found


def test_no_module_of_the_cobots_app_imports_a_higher_layer() -> None:
    offenders = {
        f"{path.relative_to(COBOTS)}: {name}"
        for path in COBOTS.rglob("*.py")
        for name in _imports(path)
        if name.startswith(HIGHER)
    }
    assert offenders == set()


@pytest.mark.django_db
def test_the_cases_app_answers_whether_a_cobot_is_in_use_and_its_queue(
    organisation: Organisation, engineer: User, operator: User, cobot: Cobot
) -> None:
    idle = factories.make_cobot(organisation)
    version = factories.make_version(organisation, published_by=engineer)
    case = factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)
    behind = factories.hand_over_case(version, started_by=engineer, operator=operator, cobot=cobot)

    # The first case's step was leased as the cobot was free; the second one's is queued.
    assert f"case {case.pk}" in hooks.cobot_in_use(cobot.pk)
    assert f"case {behind.pk}" not in hooks.cobot_in_use(cobot.pk)  # queued is not in use
    assert hooks.cobot_in_use(idle.pk) == ""
    assert hooks.queue_lengths([cobot.pk, idle.pk]) == {cobot.pk: 2, idle.pk: 0}
    assert jobs.lease_next_job(cobot.pk) is not None  # a worker claims the first one

    assert f"case {case.pk}" in hooks.cobot_in_use(cobot.pk)
    assert hooks.queue_lengths([cobot.pk]) == {cobot.pk: 2}
