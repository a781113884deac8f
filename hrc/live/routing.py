"""WebSocket URLs: the tablets' live socket."""

from django.urls import path

from hrc.live.consumers import TabletConsumer

websocket_urlpatterns = [path("ws/live/", TabletConsumer.as_asgi())]
