"""The API docs on a plant's network: Swagger UI and ReDoc with every other host blocked.

Every request to a host other than the server is aborted and noted; the
operations must render all the same, and nothing may have been asked of
another host. Screenshots: var/screenshots/api-docs-*.png.
"""

from collections.abc import Callable
from pathlib import Path

import pytest
from playwright.sync_api import Page, Route, expect

from tests.browser.conftest import SCREENSHOTS, assert_fits

pytestmark = pytest.mark.django_db(transaction=True)

Screenshot = Callable[[Page, str], Path]
# Swagger UI and ReDoc fetch and draw the whole schema.
RENDERED = 30_000


def _offline(page: Page, live_url: str) -> list[str]:
    """Aborts every request that is not to the server; returns the list of those aborted."""
    blocked: list[str] = []

    def only_the_server(route: Route) -> None:
        if route.request.url.startswith(f"{live_url}/"):
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    page.route("**/*", only_the_server)
    return blocked


def test_swagger_ui_renders_the_operations_with_no_other_host(
    page: Page, live_url: str, screenshot: Screenshot
) -> None:
    blocked = _offline(page, live_url)
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(str(error)))

    page.goto(f"{live_url}/api/docs/")

    operations = page.locator(".opblock")
    expect(operations.first).to_be_visible(timeout=RENDERED)
    expect(page.locator(".opblock-summary-path", has_text="/api/cases/").first).to_be_visible()
    assert operations.count() > 50
    assert blocked == []
    assert errors == []
    assert_fits(page)
    screenshot(page, "api-docs-swagger")


def test_redoc_renders_the_operations_with_no_other_host(page: Page, live_url: str) -> None:
    blocked = _offline(page, live_url)
    errors: list[str] = []
    page.on("pageerror", lambda error: errors.append(str(error)))

    page.goto(f"{live_url}/api/redoc/")

    operations = page.locator("[data-section-id^='operation/']")
    expect(operations.first).to_be_visible(timeout=RENDERED)
    assert operations.count() > 50
    assert blocked == []
    assert errors == []
    assert_fits(page)
    # The window only: the whole document is tens of thousands of pixels high.
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SCREENSHOTS / "api-docs-redoc.png"))


def test_the_api_root_lists_the_endpoints_in_the_browser(page: Page, live_url: str) -> None:
    page.goto(f"{live_url}/api/")

    expect(page.get_by_text(f'"{live_url}/api/cases/"')).to_be_visible()
    assert page.goto(f"{live_url}/api/nothing-here/").status == 404  # type: ignore[union-attr]
    expect(page.locator("body")).to_contain_text('"detail"')
