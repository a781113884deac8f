"""One navigation: the header each role sees, the start page, the organisation switcher, the API root."""

from html.parser import HTMLParser

import pytest
from django.contrib.auth.models import User
from django.test import Client
from django.urls import Resolver404, resolve

from hrc.cases.models import Case
from hrc.navigation import SESSION_KEY, _current_url
from hrc.organisations import services as organisation_services
from hrc.organisations.choices import Role
from hrc.organisations.models import Organisation
from tests import factories

pytestmark = pytest.mark.django_db

ENGINEER_PLACES = ["Patterns", "Cases", "Incidents", "Analytics", "Cobots"]


class Links(HTMLParser):
    """The links of the page's header (`header.site`) and of its start page (`div.start`), in order."""

    def __init__(self) -> None:
        super().__init__()
        self.header: list[tuple[str, str, bool]] = []  # (label, href, aria-current)
        self.start: list[str] = []
        self._open: list[str] = []  # "header", "start" or "" per open element we track
        self._link: tuple[str, bool] | None = None
        self._text = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        found = dict(attrs)
        if tag == "header" and "site" in (found.get("class") or ""):
            self._open.append("header")
        elif tag == "div" and found.get("class") == "start":
            self._open.append("start")
        elif tag in ("header", "div"):
            self._open.append("")
        if tag == "a" and found.get("href"):
            self._link = (found["href"] or "", "aria-current" in found)
            self._text = ""

    def handle_data(self, data: str) -> None:
        self._text += data

    def handle_endtag(self, tag: str) -> None:
        if tag == "a" and self._link is not None:
            href, current = self._link
            if "header" in self._open:
                self.header.append((self._text.strip(), href, current))
            if "start" in self._open:
                self.start.append(href)
            self._link = None
        elif tag in ("header", "div") and self._open:
            self._open.pop()


def _links(html: str) -> Links:
    parser = Links()
    parser.feed(html)
    return parser


def _client(user: User) -> Client:
    client = Client()
    client.force_login(user)
    return client


def _places(client: Client, path: str) -> list[str]:
    """The labels of the header's links on the page, after the brand."""
    response = client.get(path)
    assert response.status_code == 200, (path, response.status_code)
    return [label for label, _, _ in _links(response.content.decode()).header][1:]


def _administration_exists() -> bool:
    try:
        resolve("/organisation/people/")
    except Resolver404:
        return False
    return True


# The header ----------------------------------------------------------------------------------


def test_an_operator_is_offered_their_tablet_and_their_cells_tablets(
    operator: User, organisation: Organisation
) -> None:
    organisation_services.ensure_cell(organisation, "press")
    organisation_services.ensure_cell(organisation, "weld")

    assert _places(_client(operator), "/tablet/") == ["Tablet", "press", "weld"]


def test_an_engineer_is_offered_patterns_cases_incidents_analytics_and_cobots(
    engineer: User,
) -> None:
    assert _places(_client(engineer), "/patterns/") == ENGINEER_PLACES


def test_an_admin_is_offered_administration_once_it_exists(admin: User) -> None:
    places = _places(_client(admin), "/patterns/")

    administration = ["Administration"] if _administration_exists() else []
    assert places == ENGINEER_PLACES + administration


def test_a_superuser_is_also_offered_the_site_admin(admin: User) -> None:
    admin.is_superuser = admin.is_staff = True
    admin.save()

    assert _places(_client(admin), "/patterns/")[-1] == "Site admin"


def test_a_person_in_no_organisation_is_offered_no_place(loner: User) -> None:
    assert _places(_client(loner), "/") == []


def test_the_header_marks_the_place_the_page_is_in(engineer: User, choice_case: Case) -> None:
    client = _client(engineer)
    for path, place in [
        ("/cases/", "Cases"),
        ("/incidents/", "Incidents"),
        ("/analytics/", "Analytics"),
    ]:
        response = client.get(path)
        current = [label for label, _, now in _links(response.content.decode()).header if now]
        assert current == [place], path


@pytest.mark.parametrize(
    ("path", "current"),
    [
        ("/tablet/", "/tablet/"),
        ("/tablet/press/", "/tablet/press/"),
        ("/organisation/teams/", "/organisation/people/"),  # every administration page
        ("/accounts/password_change/", None),
    ],
)
def test_the_current_place_is_the_one_whose_section_holds_the_page(
    path: str, current: str | None
) -> None:
    places = ["/tablet/", "/tablet/press/", "/organisation/people/"]

    assert _current_url(path, places) == current


def test_the_header_names_the_organisation(engineer: User) -> None:
    response = _client(engineer).get("/patterns/")

    assert '<span class="organisation">Home plant</span>' in response.content.decode()


# Every link answers 200 for the role that is offered it ------------------------------------


@pytest.mark.parametrize("role", [Role.OPERATOR, Role.ENGINEER, Role.ADMIN])
def test_every_link_of_the_start_page_and_header_lets_the_role_in(
    role: Role, organisation: Organisation, choice_case: Case
) -> None:
    user = factories.make_member(organisation, role)
    user.is_superuser = user.is_staff = role == Role.ADMIN  # Site admin too
    user.save()
    organisation_services.ensure_cell(organisation, "press")
    client = _client(user)
    start = client.get("/", follow=True)
    assert start.status_code == 200
    links = _links(start.content.decode())
    hrefs = {href for _, href, _ in links.header} | set(links.start)
    assert len(hrefs) > 1

    # The brand ("/") sends an operator on to the tablet: where a link ends is what counts.
    refused = {href: client.get(href, follow=True).status_code for href in hrefs}

    assert {href: status for href, status in refused.items() if status != 200} == {}


# The start page -----------------------------------------------------------------------------


def test_an_operator_is_sent_from_the_start_page_to_the_tablet(operator: User) -> None:
    response = _client(operator).get("/")

    assert response.status_code == 302
    assert response["Location"] == "/tablet/"


def test_signing_in_sends_an_operator_to_the_tablet_and_an_engineer_to_the_start_page(
    operator: User, engineer: User
) -> None:
    for user, landing in [(operator, "/tablet/"), (engineer, "/")]:
        client = Client()
        response = client.post(
            "/accounts/login/",
            {"username": user.get_username(), "password": factories.PASSWORD},
            follow=True,
        )
        assert response.redirect_chain[-1][0] == landing, user


def test_the_start_page_tells_an_engineer_what_to_do_first(engineer: User) -> None:
    response = _client(engineer).get("/")

    page = response.content.decode()
    assert "Draw your first pattern" in page
    assert "Running cases (0)" in page
    assert "Register a cobot" not in page  # an admin's


def test_the_start_page_counts_the_organisations_open_cases(
    engineer: User, choice_case: Case
) -> None:
    response = _client(engineer).get("/")

    assert "Running cases (1)" in response.content.decode()


def test_the_start_page_counts_nothing_of_another_organisation(
    outsider: User, choice_case: Case
) -> None:
    page = _client(outsider).get("/").content.decode()

    assert "Other plant" in page
    assert "Running cases (0)" in page
    assert "Home plant" not in page


def test_the_start_page_tells_a_person_in_no_organisation_whom_to_ask(loner: User) -> None:
    response = _client(loner).get("/")

    page = response.content.decode()
    assert response.status_code == 200
    assert "You belong to no organisation" in page
    assert "Ask an admin of your plant" in page
    assert loner.get_username() in page


def test_the_start_page_asks_a_stranger_to_sign_in() -> None:
    response = Client().get("/")

    assert response.status_code == 200
    assert 'href="/accounts/login/"' in response.content.decode()


# The organisation switcher ------------------------------------------------------------------


@pytest.fixture
def commuter(organisation: Organisation, other_organisation: Organisation) -> User:
    """An engineer at home and an operator in the other organisation."""
    user = factories.make_member(organisation, Role.ENGINEER, "cora-commuter")
    organisation_services.add_member(other_organisation, user, Role.OPERATOR)
    return user


def test_a_person_in_several_organisations_switches_and_works_in_the_chosen_one(
    commuter: User, other_organisation: Organisation
) -> None:
    client = _client(commuter)
    assert 'name="organisation"' in client.get("/").content.decode()  # the switcher

    response = client.post("/organisation/switch/", {"organisation": other_organisation.pk})

    assert response.status_code == 302
    assert client.session[SESSION_KEY] == other_organisation.pk
    # An operator there: the start page sends them to the tablet, the header offers it.
    assert client.get("/")["Location"] == "/tablet/"
    assert _places(client, "/tablet/") == ["Tablet"]


def test_the_switcher_refuses_an_organisation_the_person_is_not_in(
    engineer: User, other_organisation: Organisation
) -> None:
    client = _client(engineer)

    response = client.post("/organisation/switch/", {"organisation": other_organisation.pk})

    assert response.status_code == 404
    assert "organisation:" in response.content.decode()
    assert SESSION_KEY not in client.session
    assert "Other plant" not in client.get("/").content.decode()


def test_the_switcher_refuses_an_id_that_is_not_a_number(engineer: User) -> None:
    client = _client(engineer)

    response = client.post("/organisation/switch/", {"organisation": "home"})

    assert response.status_code == 400
    assert "organisation: choose one of your organisations." in response.content.decode()
    assert SESSION_KEY not in client.session


@pytest.mark.parametrize("written", ["²", "٢"])  # isdigit() says yes to both; int() reads "٢"
def test_the_switcher_refuses_an_id_in_other_digits_than_ascii(
    commuter: User, written: str
) -> None:
    client = _client(commuter)

    response = client.post("/organisation/switch/", {"organisation": written})

    assert response.status_code == 400
    assert "organisation: choose one of your organisations." in response.content.decode()
    assert SESSION_KEY not in client.session


def test_the_switcher_takes_only_a_post_from_a_signed_in_person(
    commuter: User, other_organisation: Organisation
) -> None:
    assert _client(commuter).get("/organisation/switch/").status_code == 405
    stranger = Client().post("/organisation/switch/", {"organisation": other_organisation.pk})
    assert stranger.status_code == 302
    assert stranger["Location"].startswith("/accounts/login/")


def test_a_person_in_one_organisation_has_no_switcher(engineer: User) -> None:
    assert 'name="organisation"' not in _client(engineer).get("/").content.decode()


# The API root and its 404s ------------------------------------------------------------------


def test_the_api_root_lists_the_endpoints(engineer: User) -> None:
    response = _client(engineer).get("/api/", HTTP_ACCEPT="application/json")

    assert response.status_code == 200
    body = response.json()
    for endpoint in ["cases", "patterns", "pattern-versions", "cobots", "work-items", "docs"]:
        assert body[endpoint].startswith("http://testserver/api/"), endpoint
    assert body["cases"] == "http://testserver/api/cases/"
    assert body["redoc"] == "http://testserver/api/redoc/"
    assert not [url for url in body.values() if "{" in url or "(?P" in url]


def test_an_address_under_api_that_nothing_serves_answers_a_json_404() -> None:
    response = Client().get("/api/no-such-thing/")

    assert response.status_code == 404
    assert response.json() == {
        "detail": "No API endpoint at /api/no-such-thing/. The endpoints are listed at /api/."
    }


def test_an_api_address_without_its_slash_says_where_the_endpoint_is(engineer: User) -> None:
    response = _client(engineer).get("/api/cases")

    assert response.status_code == 404
    assert "Did you mean /api/cases/?" in response.json()["detail"]


def test_another_organisations_object_under_the_api_is_still_a_json_404(
    outsider: User, choice_case: Case
) -> None:
    response = _client(outsider).get(f"/api/cases/{choice_case.pk}/")

    assert response.status_code == 404
    assert "detail" in response.json()


@pytest.mark.parametrize("path", ["/api/docs/", "/api/redoc/"])
def test_the_api_docs_load_nothing_from_another_host(path: str) -> None:
    page = Client().get(path).content.decode()

    assert "/static/drf_spectacular_sidecar/" in page
    assert "https://" not in page
    assert "http://" not in page
