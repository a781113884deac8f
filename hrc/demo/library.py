"""The example library in the demo organisation: each file published, its actors mapped.

An example whose file changed is published as the pattern's next version;
an unchanged one is left alone. Each version without a default actor
mapping gets one, so a case of any example can start at once: operators are
the demo team, cobot actors the demo cobots in turn, device actors the floor's device of
their kind.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from django.contrib.auth.models import User
from django.core.exceptions import ValidationError
from django.db import transaction

from hrc.cases import services as case_services
from hrc.cases.nets import case_net
from hrc.cobots.models import Cobot
from hrc.engine import FormatError
from hrc.engine.taskconfig import device_kind_of
from hrc.errors import Invalid
from hrc.organisations.models import Organisation, Team
from hrc.patterns import services as pattern_services
from hrc.patterns.models import PatternModel, PatternVersion
from hrc.patterns.selectors import latest_version
from hrc.patterns.services import PublishRefused

EXAMPLES_DIR = Path(__file__).resolve().parents[1] / "patterns" / "examples"
# The prototype's seven use cases (and hrc's variant of the second), runnable with their data,
# beside the thesis' examples.
USE_CASES = "use_cases"


@dataclass(frozen=True)
class Loaded:
    """What became of one example file: `refused` is None when it was published or unchanged."""

    file: str
    outcome: str
    refused: str | None = None


def load_examples(
    organisation: Organisation,
    engineer: User,
    folder: Path,
    team: Team,
    cobots: Sequence[Cobot],
) -> list[Loaded]:
    """Publishes every example file in `folder` (example_files) and maps each version's actors."""
    results = []
    for path in example_files(folder):
        try:
            version, outcome = ensure_published(organisation, engineer, path)
        except (OSError, ValueError, FormatError, ValidationError, PublishRefused) as exc:
            results.append(Loaded(path.name, "not loaded", _reason(exc)))
            continue
        try:
            map_actors(version, team, cobots)
        except Invalid as exc:  # published, but a case must name its performers itself
            outcome += f"; actors not mapped: {exc}"
        results.append(Loaded(path.name, outcome))
    return results


def example_files(folder: Path) -> list[Path]:
    """The *.json in `folder`, then those in its use_cases/ folder, each sorted by name."""
    return sorted(folder.glob("*.json")) + sorted((folder / USE_CASES).glob("*.json"))


@transaction.atomic
def ensure_published(
    organisation: Organisation, engineer: User, path: Path
) -> tuple[PatternVersion, str]:
    """Makes the file's document the latest published version of the pattern of its name.

    Returns the version and what was done. Raises OSError, ValueError (not
    JSON), FormatError, ValidationError or PublishRefused.
    """
    document = json.loads(path.read_text(encoding="utf-8"))
    name = document.get("name") if isinstance(document, dict) else None
    name = name if isinstance(name, str) and name.strip() else path.stem
    pattern = PatternModel.objects.filter(organisation=organisation, name=name).first()
    if pattern is None:
        pattern = pattern_services.create_pattern(
            organisation, name=name, created_by=engineer, draft=document
        )
    else:
        latest = latest_version(pattern)
        if latest is not None and latest.document == document:
            return latest, f"{name!r} unchanged (version {latest.number})"
        pattern_services.update_pattern(pattern, draft=document)
    version = pattern_services.publish_pattern(pattern, published_by=engineer)
    return version, f"{name!r} published as version {version.number}"


def map_actors(version: PatternVersion, team: Team, cobots: Sequence[Cobot]) -> None:
    """Gives a version without a default mapping one: operators → `team`, cobots → `cobots` in turn.

    A mapping someone set (the API, the admin) is kept. Raises Invalid when
    the version cannot run or the organisation lacks what it needs.
    """
    if version.default_actor_mapping or not cobots:
        return
    mapping: dict[str, dict[str, int]] = {}
    turn = 0
    for actor in case_net(version).pattern.actors:
        if device_kind_of(actor) is not None:
            continue  # the floor's only device of its kind (mapping.py's default)
        if actor.type == "cobot":
            mapping[actor.id] = {"cobot": cobots[turn % len(cobots)].pk}
            turn += 1
        else:
            mapping[actor.id] = {"team": team.pk}
    case_services.set_default_actor_mapping(version, mapping)


def _reason(exc: Exception) -> str:
    if isinstance(exc, PublishRefused):
        messages = [error.get("message", "") for error in exc.report.get("errors", [])]
        return "the check failed: " + " ".join(messages)
    return str(exc)
