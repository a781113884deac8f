from django.apps import AppConfig


class PatternsConfig(AppConfig):
    name = "hrc.patterns"
    verbose_name = "Collaboration patterns"
