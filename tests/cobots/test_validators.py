import pytest
from django.core.exceptions import ValidationError

from hrc.cobots.validators import validate_credentials_source, validate_endpoint


@pytest.mark.parametrize(
    "endpoint",
    [
        "opc.tcp://sim-cobot1:4840",
        "opc.tcp://192.168.0.17:4840/urua",
        "opc.tcp://cobot.plant.local",
    ],
)
def test_opc_ua_endpoints_are_accepted(endpoint: str) -> None:
    validate_endpoint(endpoint)


@pytest.mark.parametrize(
    "endpoint",
    [
        "http://cobot1:4840",
        "cobot1:4840",
        "opc.tcp://",
        "opc.tcp://cobot1:notaport",
        "opc.tcp://cobot1:99999",
        "opc.tcp://user:secret@cobot1:4840",
    ],
)
def test_other_endpoints_are_refused(endpoint: str) -> None:
    with pytest.raises(ValidationError):
        validate_endpoint(endpoint)


@pytest.mark.parametrize("source", ["none", "secret:cobot1", "secret:ur10.plant-A_2"])
def test_credentials_references_are_accepted(source: str) -> None:
    validate_credentials_source(source)


@pytest.mark.parametrize("source", ["env:COBOTS_CREDENTIALS", "file:/run/secrets/cobot1"])
def test_the_workers_environment_and_files_are_refused_with_what_to_do_instead(
    source: str,
) -> None:
    with pytest.raises(ValidationError, match="creates a named credentials secret") as refused:
        validate_credentials_source(source)
    assert "secret:NAME" in refused.value.messages[0]


@pytest.mark.parametrize(
    "source", ["hunter2", "env:", "secret:", "secret:a b", "secret:../x", "none:x", ""]
)
def test_anything_that_might_be_a_secret_is_refused(source: str) -> None:
    with pytest.raises(ValidationError):
        validate_credentials_source(source)
