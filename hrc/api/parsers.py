"""Request parsers that refuse, as 400 or 413, what would otherwise become a 500.

- nesting deep enough to overflow the stack (json raises RecursionError, which
  DRF's JSONParser does not catch);
- values PostgreSQL's jsonb refuses (NUL, Infinity, NaN);
- a body over DATA_UPLOAD_MAX_MEMORY_SIZE. DRF 3.18 already reads JSON bodies
  through Django's `request.body`, which checks the limit; `read_limited`
  checks again so the limit holds whatever stream DRF hands over.
"""

import json
from collections.abc import Mapping
from typing import IO, Any

from django.conf import settings
from django.core.exceptions import RequestDataTooBig
from django.http import HttpRequest
from rest_framework.exceptions import ParseError
from rest_framework.parsers import BaseParser, JSONParser

from hrc.patterns.documents import storage_problem


def body_limit() -> int:
    return int(settings.DATA_UPLOAD_MAX_MEMORY_SIZE or 0) or 2 * 1024 * 1024


def read_limited(stream: IO[bytes], parser_context: Mapping[str, Any] | None) -> bytes:
    """The whole body; raises RequestDataTooBig (→ 413) past the limit, declared or actual."""
    limit = body_limit()
    request = (parser_context or {}).get("request")
    meta = getattr(request, "META", {})
    declared = meta.get("CONTENT_LENGTH") or meta.get("HTTP_CONTENT_LENGTH") or "0"
    if declared.isascii() and declared.isdigit() and int(declared) > limit:
        raise RequestDataTooBig("The request body is larger than the limit.")
    body = stream.read(limit + 1)
    if len(body) > limit:
        raise RequestDataTooBig("The request body is larger than the limit.")
    return body


def parse_json_body(body: bytes) -> Any:
    """Parsed JSON; raises ParseError (400) for bad syntax and values the database refuses."""
    try:
        data = json.loads(body, parse_constant=_refuse_constant)
    except RecursionError:
        raise ParseError("JSON parse error - the JSON is nested too deeply.") from None
    except ValueError as exc:  # JSONDecodeError, UnicodeDecodeError, huge integers
        raise ParseError(f"JSON parse error - {exc}") from None
    problem = storage_problem(data)
    if problem:
        raise ParseError(f"JSON parse error - {problem}")
    return data


def read_body(request: HttpRequest) -> bytes:
    """The raw body of a request whose view reads it itself; RequestDataTooBig past the limit."""
    body = request.body  # Django refuses a declared length over the limit here
    if len(body) > body_limit():
        raise RequestDataTooBig("The request body is larger than the limit.")
    return body


class LimitedJSONParser(JSONParser):
    """JSON within the body limit, with only values the database can store."""

    def parse(
        self,
        stream: IO[Any],
        media_type: str | None = None,
        parser_context: Mapping[str, Any] | None = None,
    ) -> Any:
        return parse_json_body(read_limited(stream, parser_context))


def _refuse_constant(name: str) -> None:
    raise ValueError(f"{name} is not a JSON number")


class XMLBodyParser(BaseParser):
    """Accepts an XML body (PNML, BPMN) for a view that reads `request.body` itself.

    Parsing happens in the view, with the hostile-XML guards; this only lets
    DRF get past the body when something asks for `request.data` first (the
    CSRF check of a signed-in browser does), instead of answering 415.
    """

    media_type = "application/xml"

    def parse(
        self,
        stream: IO[Any],
        media_type: str | None = None,
        parser_context: Mapping[str, Any] | None = None,
    ) -> Any:
        read_limited(stream, parser_context)
        return {}


class TextXMLParser(XMLBodyParser):
    media_type = "text/xml"
