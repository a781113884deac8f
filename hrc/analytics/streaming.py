"""A download that streams on both servers: WSGI (and the test client) and ASGI (daphne).

Django serves a synchronous iterator under ASGI only by reading all of it
first (with a warning), and an asynchronous one under WSGI the same way; so
the response gets the kind its server takes. Under ASGI the chunks are pulled
in batches on the request's thread (thread-sensitive), where its database
connection and server-side cursors live.

A stream that fails after its headers went out cannot change its status: it is
logged, its source is closed (with its server-side cursor) and the body ends
there, cut short. Left to propagate, the failure would skip Django's end of
request under ASGI: the body would never end and the request's database
connection would never go back to the pool.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import AsyncIterator, Generator, Iterator

from asgiref.sync import sync_to_async
from django.core.handlers.asgi import ASGIRequest
from django.http import HttpRequest, StreamingHttpResponse

logger = logging.getLogger(__name__)

# Chunks per trip to the request's thread under ASGI.
ASYNC_BATCH = 64


def streamed(
    request: HttpRequest, chunks: Iterator[str], *, content_type: str, filename: str
) -> StreamingHttpResponse:
    """`chunks` as a download named `filename`."""
    guarded = _ended_on_failure(chunks, filename)
    content = _batches(guarded) if isinstance(request, ASGIRequest) else guarded
    response = StreamingHttpResponse(content, content_type=content_type)
    response["Content-Disposition"] = f'attachment; filename="{filename}"'
    return response


async def _batches(chunks: Iterator[str]) -> AsyncIterator[str]:
    def take() -> list[str]:
        return list(itertools.islice(chunks, ASYNC_BATCH))

    pull = sync_to_async(take, thread_sensitive=True)
    while batch := await pull():
        yield "".join(batch)


def _ended_on_failure(chunks: Iterator[str], filename: str) -> Generator[str]:
    try:
        yield from chunks
    except Exception:
        logger.exception("The download %s failed part-way; its body ends here.", filename)
    finally:
        close = getattr(chunks, "close", None)
        if close is not None:
            close()
