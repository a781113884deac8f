from importlib import import_module

from django.apps import AppConfig


class LiveConfig(AppConfig):
    name = "hrc.live"
    verbose_name = "Live tablets"

    def ready(self) -> None:
        # receivers.py registers this app's answers to the inner apps' hooks. It imports
        # models, which Django allows only once every app is loaded, that is, here.
        import_module(f"{self.name}.receivers")
