from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.gateway.fake_ur import FakeUR, running_fake_ur


@pytest.fixture
def fake_ur() -> Iterator[FakeUR]:
    with running_fake_ur() as fake:
        yield fake
