"""Signing in through the browser: the entry to the tablets and the editor."""

from collections.abc import Callable
from pathlib import Path

import pytest
from django.contrib.auth.models import User
from playwright.sync_api import Page, expect

pytestmark = pytest.mark.django_db(transaction=True)


def test_a_member_signs_in_and_sees_their_name(
    page: Page,
    operator: User,
    sign_in: Callable[[Page, User], None],
    screenshot: Callable[[Page, str], Path],
) -> None:
    sign_in(page, operator)

    expect(page.locator("header.site .who")).to_have_text(operator.get_username())
    screenshot(page, "home-signed-in")


def test_a_wrong_password_is_refused_with_a_message(
    page: Page, live_url: str, operator: User, screenshot: Callable[[Page, str], Path]
) -> None:
    page.goto(f"{live_url}/accounts/login/")
    page.get_by_label("User name").fill(operator.get_username())
    page.get_by_label("Password").fill("not-the-password")
    page.get_by_role("button", name="Sign in").click()

    expect(page.get_by_role("alert")).to_contain_text("did not match")
    screenshot(page, "sign-in-refused")
