from django.apps import AppConfig


class CasesConfig(AppConfig):
    name = "hrc.cases"
    verbose_name = "Running cases"

    def ready(self) -> None:
        # Load the Celery app with Django, so tasks sent from the web process use the
        # configured broker, not Celery's default one. (Not in hrc/__init__.py: the
        # engine under hrc/ must import without Django, and Celery's app loads it.)
        import hrc.celery  # noqa: F401
        from hrc.cases import selectors, services
        from hrc.cobots import hooks
        from hrc.organisations import hooks as organisation_hooks

        # The cobots app asks whether a case is using a cobot before a person's command.
        hooks.register_cobot_use(
            in_use=selectors.cobot_in_use, queue_lengths=selectors.cobot_queue_lengths
        )
        # A deactivated person's tasks go back to their candidates.
        organisation_hooks.register_member_leaving(services.hand_back_work_items)
