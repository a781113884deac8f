"""One navigation in a real browser: each role lands where it works, the header fits.

Screenshots: var/screenshots/navigation-*.png (the start page and header at
1280×800, the operator's tablet header at 1024×768 too).
"""

from collections.abc import Callable
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Page, ViewportSize, expect

from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from tests import factories
from tests.browser.conftest import assert_fits

pytestmark = pytest.mark.django_db(transaction=True)

Screenshot = Callable[[Page, str], Path]
SignIn = Callable[[Page, User], None]
SMALL_TABLET = ViewportSize(width=1024, height=768)
# The header on the tablet: one row of 48 px targets and its padding.
COMPACT_HEADER = 70


def test_an_operator_signs_in_and_lands_on_the_tablet_under_a_compact_header(
    page: Page,
    live_url: str,
    organisation: Organisation,
    operator: User,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    organisation_services.ensure_cell(organisation, "press")

    sign_in(page, operator)

    assert page.url == f"{live_url}/tablet/"
    header = page.locator("header.site")
    expect(header.get_by_role("link", name="Tablet")).to_have_attribute("aria-current", "page")
    expect(header.get_by_role("link", name="Cases")).to_have_count(0)
    expect(header.locator(".organisation")).to_have_text("Home plant")
    assert_fits_and_compact(page)
    screenshot(page, "navigation-operator-tablet")

    page.set_viewport_size(SMALL_TABLET)
    header.get_by_text("Cells ▾").click()
    header.get_by_role("link", name="press").click()
    page.wait_for_url(f"{live_url}/tablet/press/")
    # In the closed Cells menu: marked all the same.
    expect(header.locator("a[href='/tablet/press/']")).to_have_attribute("aria-current", "page")
    assert_fits_and_compact(page)
    screenshot(page, "navigation-operator-tablet-1024")


def test_an_engineer_signs_in_to_the_start_page_and_moves_through_the_header(
    page: Page, live_url: str, engineer: User, sign_in: SignIn, screenshot: Screenshot
) -> None:
    sign_in(page, engineer)

    assert page.url == f"{live_url}/"
    expect(page.get_by_role("heading", name="Home plant")).to_be_visible()
    expect(page.get_by_role("link", name="Draw your first pattern")).to_be_visible()
    assert_fits_and_compact(page)
    screenshot(page, "navigation-engineer-start")

    header = page.locator("header.site")
    for place, path in [
        ("Cases", "/cases/"),
        ("Analytics", "/analytics/"),
        ("Patterns", "/patterns/"),
    ]:
        header.get_by_role("link", name=place, exact=True).click()
        page.wait_for_url(f"{live_url}{path}")
        expect(header.get_by_role("link", name=place, exact=True)).to_have_attribute(
            "aria-current", "page"
        )
    assert_fits_and_compact(page)  # the editor's height leaves room for one header row
    screenshot(page, "navigation-engineer-patterns")


def test_an_admin_in_two_organisations_switches_between_them(
    page: Page,
    live_url: str,
    organisation: Organisation,
    other_organisation: Organisation,
    sign_in: SignIn,
    screenshot: Screenshot,
) -> None:
    admin = factories.make_member(organisation, Role.ADMIN, "ada-two-plants")
    admin.is_superuser = admin.is_staff = True
    admin.save()
    organisation_services.add_member(other_organisation, admin, Role.OPERATOR)

    sign_in(page, admin)

    header = page.locator("header.site")
    expect(header.get_by_role("link", name="Site admin")).to_be_visible()
    expect(header.get_by_label("Organisation")).to_have_value(str(organisation.pk))
    page.set_viewport_size(SMALL_TABLET)
    assert_fits(page)  # the header may take two rows here, never more width
    screenshot(page, "navigation-admin-start-1024")
    page.set_viewport_size(ViewportSize(width=1280, height=800))
    assert_fits_and_compact(page)
    screenshot(page, "navigation-admin-start")

    header.get_by_label("Organisation").select_option(str(other_organisation.pk))
    header.get_by_role("button", name="Switch").click()

    page.wait_for_url(f"{live_url}/tablet/")  # an operator there
    expect(header.get_by_label("Organisation")).to_have_value(str(other_organisation.pk))
    expect(header.get_by_role("link", name="Patterns")).to_have_count(0)


def test_a_person_in_no_organisation_is_told_whom_to_ask(
    page: Page, loner: User, sign_in: SignIn, screenshot: Screenshot
) -> None:
    sign_in(page, loner)

    expect(page.get_by_role("heading", name="You belong to no organisation")).to_be_visible()
    expect(page.locator(".start")).to_contain_text(loner.get_username())
    assert_fits_and_compact(page)
    screenshot(page, "navigation-no-organisation")


def assert_fits_and_compact(page: Page) -> None:
    assert_fits(page)
    box = page.locator("header.site").bounding_box()
    assert box is not None
    assert box["height"] <= COMPACT_HEADER, f"the header is {box['height']} px high"
