"""Every page under the Content-Security-Policy, in a real browser, against `manage.py demo`.

Each role opens the pages it works in (the editor, the tablet, the supervisor and case
pages, the cobots, the organisation's administration, analytics, the API's docs and
browsable pages, the site admin) and each page must both carry the policy and work
under it: the editor checks its pattern, the tablet's socket connects, the case page
goes live, Swagger UI and ReDoc draw the operations, the admin's cobot page reads the
live state. Any `securitypolicyviolation` or console line about the policy fails the
test, on whichever page it happened.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable, Iterator

import pytest
from playwright.sync_api import (
    Browser,
    BrowserContext,
    ConsoleMessage,
    Dialog,
    Page,
    Response,
    expect,
)

from tests.browser.conftest import TABLET
from tests.demo.rig import DemoRun
from tests.support.paths import ROOT

SUPERUSER = ("root", "Csp-test-superuser-7")
LIVE = 30_000
# Every violation, reported from the page to the test with where it happened.
LISTEN = """
document.addEventListener("securitypolicyviolation", (event) => {
  window.hrcViolation(`${event.violatedDirective} blocked ${event.blockedURI || "inline"} `
    + `at ${event.sourceFile || document.location.pathname}:${event.lineNumber}`);
});
"""
# ReDoc's footer always asks Redocly's CDN for its logo; the policy stopping that request
# is the policy keeping the browser on the server (as the plant's network would), not a
# page broken by it. Nothing else may be refused.
REDOCLY_LOGO = "https://cdn.redoc.ly/redoc/logo-mini.svg"


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Iterator[DemoRun]:
    workdir = tmp_path_factory.mktemp("demo")
    run = DemoRun(workdir, database_url=f"sqlite:///{workdir / 'demo.sqlite3'}").start()
    # The site admin is for superusers; the demo's admin is the organisation's, not one.
    subprocess.run(
        [sys.executable, "manage.py", "createsuperuser", "--noinput",
         "--username", SUPERUSER[0], "--email", "root@example.com"],
        cwd=ROOT, env={**run.environment, "DJANGO_SUPERUSER_PASSWORD": SUPERUSER[1]},
        check=True, capture_output=True,
    )  # fmt: skip
    yield run
    run.stop()


class Watched:
    """A signed-in browser page whose policy violations and document headers are noted."""

    def __init__(self, context: BrowserContext, demo: DemoRun) -> None:
        self.demo = demo
        self.violations: list[str] = []
        self.unprotected: list[str] = []
        context.expose_function("hrcViolation", self._violation)
        context.add_init_script(LISTEN)
        self.page = context.new_page()
        self.page.on("console", self._console)
        self.page.on("response", self._response)

    def _violation(self, line: str) -> None:
        self.violations.append(line)

    def _console(self, message: ConsoleMessage) -> None:
        if "Content Security Policy" in message.text or message.text.startswith("Refused to"):
            self.violations.append(f"console: {message.text}")

    def _response(self, response: Response) -> None:
        # Every page the browser opens, and the frames and scripts it loads from the server.
        if response.request.resource_type != "document" or not response.url.startswith(
            self.demo.url
        ):
            return
        policy = response.headers.get("content-security-policy", "")
        if "script-src 'self'" not in policy or "default-src 'self'" not in policy:
            self.unprotected.append(f"{response.url}: {policy or 'no policy'}")

    def sign_in(self, username: str, password: str) -> None:
        self.page.goto(f"{self.demo.url}/accounts/login/")
        self.page.get_by_label("User name").fill(username)
        self.page.get_by_label("Password").fill(password)
        self.page.get_by_role("button", name="Sign in").click()
        self.page.wait_for_url(lambda url: "/accounts/login/" not in url)

    def open(self, path: str) -> Page:
        self.page.goto(f"{self.demo.url}{path}")
        return self.page

    def assert_clean(self) -> None:
        refused = [line for line in self.violations if REDOCLY_LOGO not in line]
        assert not refused, refused
        assert not self.unprotected, self.unprotected


@pytest.fixture
def watched(browser: Browser, demo: DemoRun) -> Iterator[Callable[[str, str], Watched]]:
    contexts: list[BrowserContext] = []

    def signed_in(username: str, password: str) -> Watched:
        context = browser.new_context(viewport=TABLET)
        contexts.append(context)
        session = Watched(context, demo)
        session.sign_in(username, password)
        return session

    yield signed_in
    for context in contexts:
        context.close()


def _heading(page: Page, name: str) -> None:
    expect(page.get_by_role("heading", name=name, exact=True)).to_be_visible()


def test_the_engineers_pages_work_under_the_policy(
    watched: Callable[[str, str], Watched], demo: DemoRun
) -> None:
    session = watched("engineer", demo.passwords()["engineer"])

    page = session.open("/patterns/")
    page.locator("table tbody tr").first.get_by_role("link", name="Open").click()
    expect(page.locator("#hrc-editor")).to_have_attribute("data-ready", "true")
    expect(page.get_by_label("Pattern class")).to_have_attribute("data-valid", "true", timeout=LIVE)
    # The legend's colours are set through the style object, which the policy allows.
    time = page.locator(".hrc-legend-row[data-type='time'] b")
    expect(time).to_have_css("color", "rgb(31, 95, 191)")

    case = next(iter(demo.started_cases().values()))
    page = session.open(f"/cases/{case}/")
    expect(page.locator("svg.net")).to_be_visible()
    expect(page.locator("#live-status")).to_have_attribute("data-live", "socket", timeout=LIVE)
    page = session.open("/cases/")
    _heading(page, "Cases")
    expect(page.locator(".list-head")).to_have_css("display", "flex")  # its stylesheet applies
    page = session.open("/incidents/")
    expect(page.locator("#live-status")).to_have_text("Live", timeout=LIVE)
    page = session.open("/cases/new/")
    _heading(page, "Start a case")

    page = session.open("/analytics/")
    _heading(page, "Analytics")
    page.locator("table a").first.click()
    expect(page.locator(".page-head")).to_have_css("display", "flex")

    page = session.open("/cobots/")
    page.get_by_role("link", name="cobot1").click()
    expect(page.locator('#state [data-field="RobotMode"]')).not_to_have_text("", timeout=LIVE)
    session.assert_clean()


def test_the_api_documents_work_under_the_policy(
    watched: Callable[[str, str], Watched], demo: DemoRun
) -> None:
    session = watched("engineer", demo.passwords()["engineer"])

    page = session.open("/api/docs/")
    expect(page.locator(".opblock").first).to_be_visible(timeout=LIVE)
    page = session.open("/api/redoc/")
    expect(page.locator("[data-section-id^='operation/']").first).to_be_visible(timeout=LIVE)
    page = session.open("/api/")
    expect(page.get_by_text(f'"{demo.url}/api/cases/"')).to_be_visible()
    case = next(iter(demo.started_cases().values()))
    page = session.open(f"/api/cases/{case}/")
    page.locator("#extra-actions-menu").click()
    expect(page.locator("[aria-labelledby='extra-actions-menu']")).to_be_visible()
    # Signing out is a form now, not an inline onclick.
    page.get_by_role("link", name="engineer").click()
    page.get_by_role("button", name="Log out").click()
    expect(page.get_by_role("link", name="Log in")).to_be_visible()
    session.assert_clean()


def test_the_operators_tablet_works_under_the_policy(
    watched: Callable[[str, str], Watched], demo: DemoRun
) -> None:
    session = watched("operator1", demo.passwords()["operator1"])

    page = session.open("/tablet/")
    expect(page.locator("#tablet")).to_have_attribute("data-status", "live", timeout=LIVE)
    expect(page.locator(".cobots .cobot")).to_have_count(2)
    session.assert_clean()


def test_the_admins_pages_work_under_the_policy(
    watched: Callable[[str, str], Watched], demo: DemoRun
) -> None:
    session = watched("admin", demo.passwords()["admin"])

    page = session.open("/organisation/people/")
    _heading(page, "People of Demo plant")
    page = session.open("/organisation/teams/")
    page.locator("table a").first.click()
    # The confirmation is asked by the site's script (data-confirm), not an onsubmit.
    questions: list[str] = []

    def decline(dialog: Dialog) -> None:
        questions.append(dialog.message)
        dialog.dismiss()

    page.once("dialog", decline)
    page.get_by_role("button", name="Delete the team").click()
    expect(page.get_by_role("button", name="Delete the team")).to_be_visible()
    assert questions[0].startswith("Delete the team "), questions
    page = session.open("/organisation/cells/")
    expect(page.locator("nav.organisation")).to_have_css("display", "flex")
    session.assert_clean()


def test_the_site_admin_works_under_the_policy(
    watched: Callable[[str, str], Watched], demo: DemoRun
) -> None:
    session = watched(*SUPERUSER)

    page = session.open("/admin/")
    _heading(page, "Site administration")
    page = session.open("/admin/cobots/cobot/")
    page.get_by_role("link", name="cobot1").click()
    # The live state comes from hrc/cobot-admin.js, once the inline script of this page.
    expect(page.locator("#cobot-live-state dt", has_text="reachable")).to_be_visible(timeout=LIVE)
    page = session.open("/admin/auth/user/")
    page.get_by_role("link", name="engineer").click()
    expect(page.locator("#id_username")).to_have_value("engineer")
    session.assert_clean()
