"""Local development and `make demo`: debug on, embedded defaults unless the environment says otherwise."""

from hrc.settings.base import *  # noqa: F403
from hrc.settings.env import env_bool

DEBUG = env_bool("DEBUG", True)
