"""hrc: human–robot collaboration patterns, checked formally and run on the shop floor."""

# Load the Celery app with Django, so that tasks sent from the web process use
# the configured broker and not Celery's default one.
from hrc.celery import app as celery_app

__all__ = ["celery_app"]
