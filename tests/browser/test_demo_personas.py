"""The demo's personas in a real browser, against `manage.py demo` itself (embedded defaults).

Each persona signs in with the password the demo printed and opens every
page the demo told them about (hrc.demo.organisation.Persona.pages) and the
start page; each page must show what only a working page shows, with no
script error and no failed request. Screenshots: var/screenshots/demo-*.png.
A page is one line in CHECKS; a persona's pages are listed once, in Persona.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Page, Response, expect

from hrc.demo.library import EXAMPLES_DIR, example_files
from hrc.demo.organisation import ORGANISATION_NAME, PERSONAS, Persona
from hrc.organisations.choices import Role
from tests.demo.rig import DemoRun

Screenshot = Callable[[Page, str], Path]
# The editor checks a document a moment after it opens.
CHECKED = 15_000


def _heading(name: str) -> Callable[[Page], None]:
    return lambda page: expect(page.get_by_role("heading", name=name, exact=True)).to_be_visible()


def _tablet_works(page: Page) -> None:
    """Live socket up, both simulated cobots reported by the monitor inside the server."""
    expect(page.locator("#tablet")).to_have_attribute("data-status", "live")
    panels = page.locator(".cobots .cobot")
    expect(panels).to_have_count(2)
    for panel in panels.all():
        expect(panel.locator("dd.mode")).not_to_have_text("unknown", timeout=30_000)
        expect(panel.locator(".doing")).not_to_contain_text("unreachable")


def _editor_works(page: Page) -> None:
    """The example library is listed; the first example opens in the editor, checked valid."""
    rows = page.locator("table tbody tr")
    expect(rows).to_have_count(len(example_files(EXAMPLES_DIR)))
    rows.first.get_by_role("link", name="Open").click()
    expect(page.locator("#hrc-editor")).to_have_attribute("data-ready", "true")
    expect(page.get_by_label("Pattern class")).to_have_attribute(
        "data-valid", "true", timeout=CHECKED
    )


def _start_page_works(page: Page) -> None:
    """Operators are sent on to their tablet; the others see what to do first in the demo plant."""
    if page.url.endswith("/tablet/"):
        _tablet_works(page)
    else:
        _heading(ORGANISATION_NAME)(page)


# path → what shows that the page works. One line per page.
CHECKS: dict[str, Callable[[Page], None]] = {
    "/": _start_page_works,
    "/tablet/": _tablet_works,
    "/patterns/": _editor_works,
    "/cases/": _heading("Cases"),
    "/incidents/": lambda page: expect(page.locator("#live-status")).to_have_text("Live"),
    "/analytics/": _heading("Analytics"),
    "/organisation/people/": _heading("People of Demo plant"),
}


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Iterator[DemoRun]:
    workdir = tmp_path_factory.mktemp("demo")
    run = DemoRun(workdir, database_url=f"sqlite:///{workdir / 'demo.sqlite3'}").start()
    yield run
    run.stop()


def test_every_persona_page_is_checked() -> None:
    pages = {path for persona in PERSONAS for path in persona.pages}
    assert pages <= set(CHECKS), pages - set(CHECKS)


@pytest.mark.parametrize("persona", PERSONAS, ids=lambda persona: persona.username)
def test_the_persona_signs_in_with_the_printed_password_and_its_pages_work(
    page: Page, demo: DemoRun, persona: Persona, screenshot: Screenshot
) -> None:
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(f"script error: {error}"))

    def note_failure(response: Response) -> None:
        if response.url.startswith(demo.url) and response.status >= 400:
            errors.append(f"{response.status} {response.url}")

    page.on("response", note_failure)
    page.goto(f"{demo.url}/accounts/login/")
    page.get_by_label("User name").fill(persona.username)
    page.get_by_label("Password").fill(demo.passwords()[persona.username])
    page.get_by_role("button", name="Sign in").click()
    # Signing in sends operators to their tablet and the others to the start page.
    page.wait_for_url(f"{demo.url}/tablet/" if persona.role == Role.OPERATOR else f"{demo.url}/")

    for path in ("/", *persona.pages):
        page.goto(f"{demo.url}{path}")
        CHECKS[path](page)
        name = path.strip("/").replace("/", "-") or "home"
        screenshot(page, f"demo-{persona.username}-{name}")
    # Every place the header offers the persona lets them in (a refusal is noted above).
    header = page.locator("header.site nav.places a")
    for href in [link.get_attribute("href") for link in header.all()]:
        page.goto(f"{demo.url}{href}")
    assert not errors, errors
