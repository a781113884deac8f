from django.apps import AppConfig


class OrganisationsConfig(AppConfig):
    name = "hrc.organisations"
    verbose_name = "Organisations and people"
