"""Production: every secret comes from the environment; nothing embedded."""

from hrc.settings.base import *  # noqa: F403
from hrc.settings.env import env_bool, env_required

SECRET_KEY = env_required("SECRET_KEY")
DEBUG = False
SECURE_PROXY_SSL_HEADER = ("HTTP_X_FORWARDED_PROTO", "https")
SESSION_COOKIE_SECURE = env_bool("SESSION_COOKIE_SECURE", True)
CSRF_COOKIE_SECURE = env_bool("CSRF_COOKIE_SECURE", True)
# Browsers that once reached the site over HTTPS never try plain HTTP again for a year,
# on this host and its subdomains (a plant's internal names sit under one domain). No
# preload: that list is built into browsers and takes months to leave; a plant's
# internal name has no business there. Caddy sends the same header and redirects HTTP.
SECURE_HSTS_SECONDS = 365 * 24 * 60 * 60
SECURE_HSTS_INCLUDE_SUBDOMAINS = True
SECURE_HSTS_PRELOAD = False
# Behind Caddy every request arrives with X-Forwarded-Proto https (the compose health
# check sends it too), so this only redirects a request that bypassed the proxy.
SECURE_SSL_REDIRECT = True
