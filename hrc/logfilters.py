"""Log filters named in the settings' LOGGING."""

from __future__ import annotations

import logging

# asyncua's subscriptions log every publish answer at INFO: a line every 250 ms per
# cobot session, about 0.5 MB a minute per worker, that says nothing went wrong.
PUBLISH_CHATTER = "Publish callback called with result"


class PublishChatterToDebug(logging.Filter):
    """Demotes asyncua's per-publish line to DEBUG: shown only where DEBUG is enabled."""

    def filter(self, record: logging.LogRecord) -> bool:
        message = record.msg if isinstance(record.msg, str) else ""
        if record.levelno != logging.INFO or not message.startswith(PUBLISH_CHATTER):
            return True
        record.levelno, record.levelname = logging.DEBUG, "DEBUG"
        return logging.getLogger(record.name).isEnabledFor(logging.DEBUG)
