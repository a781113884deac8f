"""The JSON parser's limits, including the cases the test client cannot send."""

import io

import pytest
from django.core.exceptions import RequestDataTooBig
from django.test import RequestFactory, override_settings
from rest_framework.exceptions import ParseError

from hrc.api.parsers import LimitedJSONParser


def _parse(body: bytes, declared: str | None = None) -> object:
    request = RequestFactory().post("/", data=b"", content_type="application/json")
    if declared is None:
        request.META.pop("CONTENT_LENGTH", None)
    else:
        request.META["CONTENT_LENGTH"] = declared
    return LimitedJSONParser().parse(io.BytesIO(body), None, {"request": request})


@override_settings(DATA_UPLOAD_MAX_MEMORY_SIZE=100)
def test_a_body_longer_than_the_limit_is_refused_even_without_a_declared_length() -> None:
    with pytest.raises(RequestDataTooBig):
        _parse(b'{"a": "' + b"x" * 200 + b'"}')


@override_settings(DATA_UPLOAD_MAX_MEMORY_SIZE=100)
def test_a_declared_length_over_the_limit_is_refused_before_reading() -> None:
    with pytest.raises(RequestDataTooBig):
        _parse(b"{}", declared="101")


@override_settings(DATA_UPLOAD_MAX_MEMORY_SIZE=100)
def test_a_body_at_the_limit_is_read() -> None:
    body = b'{"a": "' + b"x" * 91 + b'"}'
    assert len(body) == 100
    assert _parse(body) == {"a": "x" * 91}


@pytest.mark.parametrize(
    "body",
    [b"[" * 50_000 + b"]" * 50_000, b'{"a": Infinity}', b'{"a": -1e999}', b'["\\u0000"]'],
    ids=["recursion", "infinity", "overflow", "nul"],
)
def test_values_that_would_crash_later_are_parse_errors(body: bytes) -> None:
    with pytest.raises(ParseError):
        _parse(body)


def test_utf16_json_is_read() -> None:
    assert _parse('{"a": "ü"}'.encode("utf-16")) == {"a": "ü"}


def test_a_declared_length_in_other_digits_than_ascii_is_not_read_as_one() -> None:
    # "²" passes str.isdigit() and fails int(): it was a 500.
    assert _parse(b"{}", declared="²") == {}
