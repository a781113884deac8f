"""`manage.py run_pattern --simulate` as a command on PostgreSQL and Redis: the use cases in a child
process on the tests' database (the thesis examples run through the same command in-process in
test_run_pattern.py, the use cases on Celery workers in test_use_cases.py), each completing with
constraint-true traces, as test_run_pattern_embedded.py checks them on the embedded default."""

from __future__ import annotations

from pathlib import Path

import pytest
from django.conf import settings
from django.db import connection

from hrc.cases.choices import CaseStatus
from hrc.cases.models import Case
from tests.cases.test_run_pattern_embedded import (
    EXAMPLES,
    cases_for,
    embedded_environment,
    run_and_check,
)

USE_CASES = sorted((EXAMPLES / "use_cases").glob("*.json"))


def postgresql_environment(scratch: Path) -> dict[str, str]:
    """The command's environment on this test's PostgreSQL database and the tests' Redis."""
    database = settings.DATABASES["default"]
    password = f":{database['PASSWORD']}" if database["PASSWORD"] else ""
    url = (
        f"postgres://{database['USER']}{password}@{database['HOST']}:{database['PORT']}/"
        f"{connection.settings_dict['NAME']}"
    )
    assert settings.REDIS_URL, "the tests run on Redis"
    return embedded_environment(scratch) | {"DATABASE_URL": url, "REDIS_URL": settings.REDIS_URL}


@pytest.mark.django_db(transaction=True)
@pytest.mark.parametrize("path", USE_CASES, ids=[p.stem for p in USE_CASES])
def test_each_use_case_completes_through_run_pattern_on_postgresql_and_redis(
    path: Path, tmp_path: Path
) -> None:
    cases = cases_for(path)

    elapsed = run_and_check(path, postgresql_environment(tmp_path), cases)

    # They ran here, not on a SQLite file of their own.
    assert Case.objects.filter(status=CaseStatus.COMPLETED).count() == cases
    assert not (tmp_path / "var" / "hrc.sqlite3").exists()
    print(f"{path.name}: {cases} case(s) in {elapsed:.1f} s")
