from django.apps import AppConfig


class CasesConfig(AppConfig):
    name = "hrc.cases"
    verbose_name = "Running cases"
