from django.apps import AppConfig


class LiveConfig(AppConfig):
    name = "hrc.live"
    verbose_name = "Live tablets"
