from django.apps import AppConfig


class AnalyticsConfig(AppConfig):
    """Reads only: no models of its own; it measures hrc.cases' rows."""

    name = "hrc.analytics"
    verbose_name = "Analytics"
