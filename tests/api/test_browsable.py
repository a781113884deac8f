"""The browsable API renders for a signed-in person (it is how engineers try the API)."""

import pytest
from django.contrib.auth.models import User
from django.test import Client

from hrc.patterns.models import PatternModel
from tests import factories


@pytest.mark.parametrize(
    "path",
    [
        "/api/patterns/",
        "/api/patterns/{pattern}/",
        "/api/patterns/{pattern}/versions/",
        "/api/cobots/",
        "/api/organisations/me/",
        "/api/pattern-versions/",
    ],
)
def test_the_browsable_api_renders(engineer: User, pattern: PatternModel, path: str) -> None:
    factories.make_cobot(pattern.organisation)
    client = Client()
    client.force_login(engineer)
    response = client.get(path.format(pattern=pattern.pk), HTTP_ACCEPT="text/html")
    assert response.status_code == 200
    assert response["Content-Type"].startswith("text/html")


def test_the_start_page_links_to_the_sign_in_and_the_docs(db: None) -> None:
    page = Client().get("/").content.decode()
    assert 'href="/accounts/login/"' in page
    assert 'href="/api/docs/"' in page
