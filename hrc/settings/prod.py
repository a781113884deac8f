"""Production: every secret comes from the environment; nothing embedded."""

from hrc.settings.base import *  # noqa: F403
from hrc.settings.env import env_bool, env_required

SECRET_KEY = env_required("SECRET_KEY")
DEBUG = False
SECURE_PROXY_SSL_HEADER = ("HTTP_X_FORWARDED_PROTO", "https")
SESSION_COOKIE_SECURE = env_bool("SESSION_COOKIE_SECURE", True)
CSRF_COOKIE_SECURE = env_bool("CSRF_COOKIE_SECURE", True)
