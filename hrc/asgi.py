"""ASGI entry point: HTTP through Django; WebSockets (the tablets' live socket) through Channels,
with the session's user and only from pages of an allowed host."""

import os

from django.core.asgi import get_asgi_application

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "hrc.settings.dev")

# Django first: the routing below imports models.
http = get_asgi_application()

from channels.auth import AuthMiddlewareStack  # noqa: E402
from channels.routing import ProtocolTypeRouter, URLRouter  # noqa: E402
from channels.security.websocket import AllowedHostsOriginValidator  # noqa: E402
from django.conf import settings  # noqa: E402

from hrc import urls  # noqa: E402, F401 (loaded now, not on the first request: frozen below)
from hrc.embedded import EmbeddedServices  # noqa: E402
from hrc.live.routing import websocket_urlpatterns  # noqa: E402
from hrc.process import freeze_start_up  # noqa: E402

application = ProtocolTypeRouter(
    {
        "http": http,
        "websocket": AllowedHostsOriginValidator(
            AuthMiddlewareStack(URLRouter(websocket_urlpatterns))
        ),
    }
)
if settings.HRC_INLINE_TASKS:  # no Redis: the sweeper and the cobot monitor run in this server
    application = EmbeddedServices(application)
freeze_start_up()
