from importlib import import_module

from django.apps import AppConfig


class AnalyticsConfig(AppConfig):
    """Reads only: no models of its own; it measures hrc.cases' rows."""

    name = "hrc.analytics"
    verbose_name = "Analytics"

    def ready(self) -> None:
        # receivers.py registers this app's answers to the inner apps' hooks. It imports
        # models, which Django allows only once every app is loaded, that is, here.
        import_module(f"{self.name}.receivers")
