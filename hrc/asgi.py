"""ASGI entry point: HTTP through Django; WebSocket routes join here as the live app grows."""

import os

from django.core.asgi import get_asgi_application

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "hrc.settings.dev")

application = get_asgi_application()
