"""What the organisations app does on Django's own signals, connected when Django is ready."""

from django.contrib.auth import get_user_model
from django.db.models.signals import post_save

from hrc.organisations import services

# A password is changed by the admin's forms, `changepassword`, the reset pages
# and these services alike, all through set_password() and save(): the save is the
# one place that sees every change, so the user's API keys go there.
post_save.connect(
    services.revoke_api_tokens_on_new_password,
    sender=get_user_model(),
    dispatch_uid="hrc-revoke-api-tokens-on-new-password",
)
