"""Downloads stream on both servers: a plain iterator under WSGI, batches pulled on demand
under ASGI (Django would otherwise read a synchronous iterator whole before sending)."""

import asyncio
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

from django.test import AsyncRequestFactory, RequestFactory

from hrc.analytics.streaming import ASYNC_BATCH, streamed


class Counted:
    """Chunks "0", "1", … that remember how many were taken."""

    def __init__(self, total: int) -> None:
        self.total, self.taken = total, 0

    def __iter__(self) -> Iterator[str]:
        for n in range(self.total):
            self.taken += 1
            yield str(n)


def test_under_wsgi_the_chunks_go_out_as_they_come() -> None:
    chunks = Counted(3)
    response = streamed(
        RequestFactory().get("/"), iter(chunks), content_type="text/plain", filename="x.txt"
    )
    assert response.is_async is False
    assert response["Content-Disposition"] == 'attachment; filename="x.txt"'
    assert chunks.taken == 0  # nothing is read before the server asks
    assert list(response.streaming_content) == [b"0", b"1", b"2"]  # type: ignore[arg-type]  # sync here


def test_under_asgi_batches_are_pulled_one_at_a_time() -> None:
    chunks = Counted(ASYNC_BATCH * 2 + 5)
    response = streamed(
        AsyncRequestFactory().get("/"), iter(chunks), content_type="text/plain", filename="x"
    )
    assert response.is_async is True

    async def first_batch_then_rest() -> tuple[int, list[bytes]]:
        stream = aiter(response.streaming_content)  # type: ignore[arg-type]
        first = [await anext(stream)]
        taken_after_first = chunks.taken
        return taken_after_first, first + [part async for part in stream]

    # On a thread of its own: a browser test's Playwright may have left an event loop on this one.
    with ThreadPoolExecutor(1) as thread:
        taken_after_first, parts = thread.submit(asyncio.run, first_batch_then_rest()).result()
    assert taken_after_first == ASYNC_BATCH
    assert len(parts) == 3
    assert b"".join(parts) == "".join(str(n) for n in range(chunks.total)).encode()


def failing_after(count: int, closed: list[bool]) -> Iterator[str]:
    try:
        for n in range(count):
            yield str(n)
        raise RuntimeError("the database refused the query")
    finally:
        closed.append(True)


def test_a_stream_that_fails_under_wsgi_ends_its_body_and_closes_its_source() -> None:
    closed: list[bool] = []
    response = streamed(
        RequestFactory().get("/"), failing_after(2, closed), content_type="text/plain", filename="x"
    )
    assert list(response.streaming_content) == [b"0", b"1"]  # type: ignore[arg-type]  # sync here
    assert closed == [True]


def test_a_stream_that_fails_under_asgi_ends_its_body_and_closes_its_source() -> None:
    closed: list[bool] = []
    response = streamed(
        AsyncRequestFactory().get("/"),
        failing_after(3, closed),
        content_type="text/plain",
        filename="x",
    )

    async def whole() -> list[bytes]:
        return [part async for part in response.streaming_content]  # type: ignore[union-attr]

    with ThreadPoolExecutor(1) as thread:
        parts = thread.submit(asyncio.run, whole()).result()
    assert b"".join(parts) == b"012"
    assert closed == [True]
