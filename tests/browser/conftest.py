"""A real browser against a real server: Debian's chromium driven by Playwright.

The server is `manage.py runserver` (daphne's, so HTTP and WebSockets go
through ASGI as in production) in its own process, on the test database, so
tests that use it need `transactional_db`: what a test writes must be
committed for the server to see it. Screenshots go to var/screenshots/,
which the run keeps.
"""

import os
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from django.conf import settings
from django.contrib.auth.models import User
from playwright.sync_api import (
    Browser,
    BrowserContext,
    Page,
    Playwright,
    ViewportSize,
    sync_playwright,
)

from tests import factories
from tests.cases.conftest import broker, start_worker  # noqa: F401  # the tablet tests' worker
from tests.live.server import LiveServer

CHROMIUM = "/usr/bin/chromium"
SCREENSHOTS = Path(settings.BASE_DIR) / "var" / "screenshots"
# A 10-inch tablet in landscape, the operators' device.
TABLET = ViewportSize(width=1280, height=800)

# Playwright's sync API runs an event loop in the test's thread, which makes
# Django refuse ORM calls from that thread; the tests are synchronous code
# that only looks async to Django, so the check does not apply.
os.environ.setdefault("DJANGO_ALLOW_ASYNC_UNSAFE", "true")


@pytest.fixture(scope="session")
def live_url(django_db_setup: None, tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """The base URL of an ASGI server on the test database."""
    server = LiveServer(tmp_path_factory.mktemp("server") / "server.log").start()
    yield server.url
    server.stop()


# Module scope, not session: while Playwright's sync API is up, its event loop
# counts as running in this thread, and every asyncio test that the same
# xdist worker runs after the browser tests would fail to start its own.
@pytest.fixture(scope="module")
def playwright() -> Iterator[Playwright]:
    with sync_playwright() as driver:
        yield driver


@pytest.fixture(scope="module")
def browser(playwright: Playwright) -> Iterator[Browser]:
    browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
    yield browser
    browser.close()


@pytest.fixture
def context(browser: Browser) -> Iterator[BrowserContext]:
    context = browser.new_context(viewport=TABLET, has_touch=True)
    yield context
    context.close()


@pytest.fixture
def page(context: BrowserContext) -> Page:
    return context.new_page()


@pytest.fixture
def screenshot() -> Callable[[Page, str], Path]:
    """Saves the page as var/screenshots/<name>.png and returns the path."""

    def take(page: Page, name: str) -> Path:
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        path = SCREENSHOTS / f"{name}.png"
        page.screenshot(path=str(path), full_page=True)
        return path

    return take


# Elements whose content is wider or taller than their box and is hidden
# (cut-off text, a clipped button), and how far the page runs past the viewport.
_CUT_OFF = """() => {
  const cut = [];
  for (const el of document.querySelectorAll('body *')) {
    const style = getComputedStyle(el);
    if (style.display === 'none' || style.visibility === 'hidden' || el.closest('svg')) continue;
    // perfect-scrollbar (ReDoc's menu) hides the overflow and scrolls it itself.
    if (el.classList.contains('ps')) continue;
    const clipsX = ['hidden', 'clip'].includes(style.overflowX) || style.textOverflow === 'ellipsis';
    const clipsY = ['hidden', 'clip'].includes(style.overflowY);
    if ((clipsX && el.scrollWidth > el.clientWidth + 1) || (clipsY && el.scrollHeight > el.clientHeight + 1)) {
      cut.push(el.tagName.toLowerCase() + (el.id ? '#' + el.id : '') + ': ' + (el.textContent || '').trim().slice(0, 60));
    }
  }
  return {cut, overflow: document.documentElement.scrollWidth - window.innerWidth};
}"""


def assert_fits(page: Page) -> None:
    """Fails when the page scrolls sideways or hides part of an element's content."""
    found = page.evaluate(_CUT_OFF)
    assert found["overflow"] <= 0, f"the page is {found['overflow']} px wider than the window"
    assert not found["cut"], f"cut off: {found['cut']}"


@pytest.fixture
def sign_in(live_url: str) -> Callable[[Page, User], None]:
    """Signs the user in through the sign-in form, as a person would."""

    def go(page: Page, user: User) -> None:
        page.goto(f"{live_url}/accounts/login/")
        page.get_by_label("User name").fill(user.get_username())
        page.get_by_label("Password").fill(factories.PASSWORD)
        page.get_by_role("button", name="Sign in").click()
        # Where each role lands: operators at the tablet, the others at the start page.
        page.wait_for_url(lambda url: url.startswith(live_url) and "/accounts/login/" not in url)

    return go
