from django.apps import AppConfig


class LiveConfig(AppConfig):
    name = "hrc.live"
    verbose_name = "Live tablets"

    def ready(self) -> None:
        from hrc.live import broadcast
        from hrc.organisations import hooks

        # An admin who ends a membership closes that person's sockets at once.
        hooks.register_membership_ended(broadcast.membership_ended_on_commit)
