"""`manage.py load_demo`: the demo organisation, its people, cobots and published examples."""

import io
import json
import re
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from django.core.management import CommandError, call_command

from hrc.cases import services as case_services
from hrc.cobots.models import Cobot, Device
from hrc.demo.library import example_files
from hrc.demo.management.commands.load_demo import EXAMPLES_DIR
from hrc.organisations.models import Membership, Organisation, Team
from hrc.patterns.models import PatternModel, PatternVersion
from tests import factories


def _load_demo(*args: str) -> str:
    out = io.StringIO()
    call_command("load_demo", *args, stdout=out, stderr=io.StringIO())
    return out.getvalue()


def _passwords(output: str) -> dict[str, str]:
    return dict(re.findall(r"^\s+(\S+)\s+password (\S+)", output, re.MULTILINE))


@pytest.mark.django_db
def test_it_creates_the_demo_plant_with_people_who_can_sign_in() -> None:
    output = _load_demo()
    organisation = Organisation.objects.get(name="Demo plant")
    roles = dict(
        Membership.objects.filter(organisation=organisation).values_list("user__username", "role")
    )
    assert roles == {
        "admin": "admin",
        "engineer": "engineer",
        "operator1": "operator",
        "operator2": "operator",
    }
    passwords = _passwords(output)
    assert set(passwords) == set(roles)
    for username, password in passwords.items():
        assert User.objects.get(username=username).check_password(password)
        assert username not in password
    assert len(set(passwords.values())) == len(passwords)
    admin = User.objects.get(username="admin")
    # An organisation admin, who administers at /organisation/; /admin/ is for superusers.
    assert not admin.is_staff
    assert not admin.is_superuser
    assert not User.objects.get(username="operator1").is_staff
    team = Team.objects.get(organisation=organisation)
    assert sorted(team.members.values_list("user__username", flat=True)) == [
        "operator1",
        "operator2",
    ]
    cobots = Cobot.objects.filter(organisation=organisation)
    assert sorted(cobots.values_list("name", "endpoint")) == [
        ("cobot1", "opc.tcp://127.0.0.1:4841"),
        ("cobot2", "opc.tcp://127.0.0.1:4842"),
    ]
    assert {c.driver for c in cobots} == {"simulated"}


@pytest.mark.django_db
def test_running_it_again_prints_new_passwords_and_the_old_ones_stop_working() -> None:
    first = _passwords(_load_demo())
    second = _passwords(_load_demo())
    for username in first:
        user = User.objects.get(username=username)
        assert second[username] != first[username]
        assert user.check_password(second[username])
        assert not user.check_password(first[username])


@pytest.mark.django_db
def test_keep_passwords_leaves_them_and_prints_none() -> None:
    first = _passwords(_load_demo())
    output = _load_demo("--keep-passwords")
    assert set(_passwords(output).values()) == {"(unchanged)"}
    for username, password in first.items():
        assert User.objects.get(username=username).check_password(password)
        assert password not in output


@pytest.mark.django_db
def test_every_example_can_start_a_case_with_the_demo_people_and_cobots() -> None:
    _load_demo("--strict")
    organisation = Organisation.objects.get(slug="demo-plant")
    team = Team.objects.get(organisation=organisation)
    cobots = set(Cobot.objects.filter(organisation=organisation).values_list("pk", flat=True))
    versions = PatternVersion.objects.filter(pattern__organisation=organisation)
    assert versions.exists()
    for version in versions:
        actors = {actor["id"]: actor["type"] for actor in version.document["actors"]}
        device_actors = {a["id"] for a in version.document["actors"] if "device" in a}
        mapping = version.default_actor_mapping
        assert set(mapping) == set(actors), version
        for actor, kind in actors.items():
            if actor in device_actors:
                assert Device.objects.get(pk=mapping[actor]["device"]).organisation == organisation
            elif kind == "cobot":
                assert mapping[actor]["cobot"] in cobots
            else:
                assert mapping[actor] == {"team": team.pk}
        case = case_services.start_case(version, started_by=User.objects.get(username="engineer"))
        assert case.status == "running"


@pytest.mark.django_db
def test_every_shipped_example_is_published_as_version_1() -> None:
    examples = example_files(EXAMPLES_DIR)
    assert len(examples) == 8 + 7 + 3, "the thesis' examples, the prototype's use cases, 2b, 4b, 5b"
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
        for model in (Organisation, User, Membership, Team, Cobot, PatternModel, PatternVersion)
    ]
    output = _load_demo()
    assert counts == [
        model.objects.count()
        for model in (Organisation, User, Membership, Team, Cobot, PatternModel, PatternVersion)
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


@pytest.mark.django_db
def test_the_cobots_can_point_at_the_compose_gateways() -> None:
    """What docker/README.md tells a person to run in the compose set-up."""
    _load_demo("--cobot-endpoint", "opc.tcp://gateway-{cobot}:4840")
    cobots = Cobot.objects.filter(organisation__slug="demo-plant")
    assert sorted(cobots.values_list("name", "endpoint", "credentials_source")) == [
        ("cobot1", "opc.tcp://gateway-cobot1:4840", "none"),
        ("cobot2", "opc.tcp://gateway-cobot2:4840", "none"),
    ]
    _load_demo()  # and back to make demo's loopback gateways
    assert sorted(cobots.values_list("endpoint", "credentials_source")) == [
        ("opc.tcp://127.0.0.1:4841", "none"),
        ("opc.tcp://127.0.0.1:4842", "none"),
    ]


@pytest.mark.django_db
def test_a_bad_cobot_template_is_refused_naming_what_is_wrong() -> None:
    with pytest.raises(CommandError, match="--cobot-endpoint may use"):
        _load_demo("--cobot-endpoint", "opc.tcp://{host}:4840")
    with pytest.raises(CommandError, match="OPC UA URL"):
        _load_demo("--cobot-endpoint", "http://gateway-{cobot}:4840")
    with pytest.raises(CommandError, match="credentials source"):
        _load_demo("--cobot-credentials", "secret-password")
    # A worker's variable would be every organisation's: cobots sign in with a named secret.
    with pytest.raises(CommandError, match="named credentials secret"):
        _load_demo("--cobot-credentials", "env:{COBOT}_CREDENTIALS")
    assert not Organisation.objects.filter(slug="demo-plant").exists()
