"""The simulator's one way out: values go to the gateway only when they changed."""

from __future__ import annotations

from collections.abc import Mapping

from hrc_gateway.backend import Publish, Value


class Publisher:
    """Passes changed values on to the gateway's `publish`; silent until connected."""

    def __init__(self) -> None:
        self._publish: Publish | None = None
        self._last: dict[str, Value] = {}

    def connect(self, publish: Publish) -> None:
        self._publish = publish

    def last(self, path: str) -> Value | None:
        """The last value published at `path`; None if none was."""
        return self._last.get(path)

    async def __call__(self, values: Mapping[str, Value], *, force: bool = False) -> None:
        """Publishes the values that differ from the last published ones (all with `force`)."""
        if self._publish is None:
            return
        changed = {
            path: value
            for path, value in values.items()
            if force or path not in self._last or self._last[path] != value
        }
        if not changed:
            return
        self._last.update(changed)
        await self._publish(changed)
