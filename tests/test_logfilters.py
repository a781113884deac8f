"""asyncua's per-publish chatter is DEBUG, its other lines keep their level."""

import logging

import pytest

SUBSCRIPTION_LOGGER = "asyncua.common.subscription"


def test_asyncuas_publish_answers_are_not_logged_at_info(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    logger = logging.getLogger(SUBSCRIPTION_LOGGER)

    logger.info("Publish callback called with result: %s", "PublishResult(...)")
    logger.info("Subscription created %s", 7)

    assert [r.getMessage() for r in caplog.records] == ["Subscription created 7"]


def test_they_are_there_for_whoever_asks_for_debug(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger=SUBSCRIPTION_LOGGER)

    logging.getLogger(SUBSCRIPTION_LOGGER).info("Publish callback called with result: %s", "x")

    [record] = caplog.records
    assert record.levelname == "DEBUG"
