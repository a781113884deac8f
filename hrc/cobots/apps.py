from django.apps import AppConfig


class CobotsConfig(AppConfig):
    name = "hrc.cobots"
    verbose_name = "Cobots"
