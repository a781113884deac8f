"""`manage.py load_demo`: the demo organisation, its people, cobots and published examples."""

import io
import json
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from django.core.management import CommandError, call_command

from hrc.cobots.models import Cobot
from hrc.organisations.models import Membership, Organisation
from hrc.patterns.management.commands.load_demo import EXAMPLES_DIR
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories


def _load_demo(*args: str) -> str:
    out = io.StringIO()
    call_command("load_demo", *args, stdout=out, stderr=io.StringIO())
    return out.getvalue()


@pytest.mark.django_db
def test_it_creates_the_demo_plant_with_people_who_can_sign_in() -> None:
    output = _load_demo()
    organisation = Organisation.objects.get(name="Demo plant")
    roles = dict(
        Membership.objects.filter(organisation=organisation).values_list("user__username", "role")
    )
    assert roles == {"admin": "admin", "engineer": "engineer", "operator": "operator"}
    for username in roles:
        assert User.objects.get(username=username).check_password(f"demo-{username}")
        assert f"demo-{username}" in output
    admin = User.objects.get(username="admin")
    assert admin.is_staff
    assert admin.is_superuser
    assert not User.objects.get(username="operator").is_staff
    cobots = Cobot.objects.filter(organisation=organisation)
    assert cobots.count() >= 2
    assert {c.driver for c in cobots} == {"simulated"}


@pytest.mark.django_db
def test_every_shipped_example_is_published_as_version_1() -> None:
    examples = sorted(EXAMPLES_DIR.glob("*.json"))
    assert examples, "the example library is empty"
    _load_demo("--strict")
    names = {json.loads(path.read_text())["name"] for path in examples}
    patterns = PatternModel.objects.filter(organisation__slug="demo-plant")
    assert set(patterns.values_list("name", flat=True)) == names
    assert set(PatternVersion.objects.values_list("number", flat=True)) == {1}
    assert PatternVersion.objects.count() == len(examples)
    assert all(v.report["valid"] for v in PatternVersion.objects.all())


@pytest.mark.django_db
def test_running_it_twice_changes_nothing() -> None:
    _load_demo()
    counts = [
        model.objects.count()
        for model in (Organisation, User, Membership, Cobot, PatternModel, PatternVersion)
    ]
    output = _load_demo()
    assert counts == [
        model.objects.count()
        for model in (Organisation, User, Membership, Cobot, PatternModel, PatternVersion)
    ]
    assert "unchanged" in output


@pytest.mark.django_db
def test_a_changed_example_is_published_as_the_next_version(tmp_path: Path) -> None:
    document = factories.valid_document()
    example = tmp_path / "hand_over.json"
    example.write_text(json.dumps(document))
    _load_demo("--examples", str(tmp_path))
    document["processes"][0]["transitions"][0]["label"] = "prepare the workpiece carefully"
    example.write_text(json.dumps(document))
    _load_demo("--examples", str(tmp_path))
    pattern = PatternModel.objects.get(name=document["name"])
    assert list(pattern.versions.order_by("number").values_list("number", flat=True)) == [1, 2]
    assert pattern.versions.get(number=2).document == document


@pytest.mark.django_db
def test_a_broken_example_is_reported_and_the_others_still_load(tmp_path: Path) -> None:
    (tmp_path / "a_good.json").write_text(json.dumps(factories.valid_document()))
    (tmp_path / "b_colliding.json").write_text(json.dumps(factories.document_with_duplicate_ids()))
    (tmp_path / "c_not_json.json").write_text("{")
    errors = io.StringIO()
    call_command("load_demo", "--examples", str(tmp_path), stdout=io.StringIO(), stderr=errors)
    assert "b_colliding.json" in errors.getvalue()
    assert "c_not_json.json" in errors.getvalue()
    assert PatternVersion.objects.count() == 1
    with pytest.raises(CommandError):
        _load_demo("--examples", str(tmp_path), "--strict")
