"""A download that streams on both servers: WSGI (and the test client) and ASGI (daphne).

Django serves a synchronous iterator under ASGI only by reading all of it
first (with a warning), and an asynchronous one under WSGI the same way; so
the response gets the kind its server takes. Under ASGI the chunks are pulled
in batches on the request's thread (thread-sensitive), where its database
connection and server-side cursors live.
"""

from __future__ import annotations

import itertools
from collections.abc import AsyncIterator, Iterator

from asgiref.sync import sync_to_async
from django.core.handlers.asgi import ASGIRequest
from django.http import HttpRequest, StreamingHttpResponse

# Chunks per trip to the request's thread under ASGI.
ASYNC_BATCH = 64


def streamed(
    request: HttpRequest, chunks: Iterator[str], *, content_type: str, filename: str
) -> StreamingHttpResponse:
    """`chunks` as a download named `filename`."""
    content = _batches(chunks) if isinstance(request, ASGIRequest) else chunks
    response = StreamingHttpResponse(content, content_type=content_type)
    response["Content-Disposition"] = f'attachment; filename="{filename}"'
    return response


async def _batches(chunks: Iterator[str]) -> AsyncIterator[str]:
    def take() -> list[str]:
        return list(itertools.islice(chunks, ASYNC_BATCH))

    pull = sync_to_async(take, thread_sensitive=True)
    while batch := await pull():
        yield "".join(batch)
