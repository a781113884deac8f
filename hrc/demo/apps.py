from django.apps import AppConfig


class DemoConfig(AppConfig):
    name = "hrc.demo"
    verbose_name = "Demo"
