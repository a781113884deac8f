from django.apps import AppConfig


class CobotsConfig(AppConfig):
    name = "hrc.cobots"
    verbose_name = "Cobots"

    def ready(self) -> None:
        from hrc.cobots import selectors
        from hrc.organisations import hooks

        # A cell cannot be deleted while a cobot stands in it.
        hooks.register_cell_occupants(selectors.cobots_in_cell)
