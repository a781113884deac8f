"""Settings shared by every environment.

Values that differ per deployment come from the environment through the typed
readers in `env.py`. Without DATABASE_URL or REDIS_URL the project runs on
embedded defaults (SQLite, in-memory channel layer, eager Celery) so that
`make demo` works on a bare machine.
"""

from pathlib import Path

import dj_database_url

from hrc.settings.env import env_bool, env_list, env_networks, env_str, env_url

BASE_DIR = Path(__file__).resolve().parent.parent.parent
# Where the embedded defaults keep their files (the SQLite database, the demo's logs, the
# simulated cobots' state); tests that run the embedded default point it elsewhere.
VAR_DIR = Path(env_str("HRC_VAR_DIR") or BASE_DIR / "var")

SECRET_KEY = env_str("SECRET_KEY", "dev-only-not-secret") or ""
DEBUG = env_bool("DEBUG", False)
ALLOWED_HOSTS = env_list("ALLOWED_HOSTS", ["127.0.0.1", "localhost"])

INSTALLED_APPS = [
    "daphne",
    "django.contrib.admin",
    "django.contrib.auth",
    "django.contrib.contenttypes",
    "django.contrib.sessions",
    "django.contrib.messages",
    "django.contrib.staticfiles",
    "rest_framework",
    "drf_spectacular",
    # Swagger UI and ReDoc as static files: /api/docs/ needs no CDN.
    "drf_spectacular_sidecar",
    "channels",
    # Login lockout on every path that signs in (hrc.signin says why this and how).
    "axes",
    "hrc.organisations",
    "hrc.patterns",
    "hrc.cobots",
    "hrc.cases",
    "hrc.live",
    "hrc.analytics",
    "hrc.demo",
]

MIDDLEWARE = [
    "django.middleware.security.SecurityMiddleware",
    "hrc.middleware.ContentSecurityPolicyMiddleware",
    "django.contrib.sessions.middleware.SessionMiddleware",
    "django.middleware.common.CommonMiddleware",
    "django.middleware.csrf.CsrfViewMiddleware",
    "django.contrib.auth.middleware.AuthenticationMiddleware",
    "django.contrib.messages.middleware.MessageMiddleware",
    "django.middleware.clickjacking.XFrameOptionsMiddleware",
    "hrc.middleware.RefusalMiddleware",
    "hrc.middleware.DatabaseUnavailableMiddleware",
    # Last, as axes asks: it turns a lockout into its 429 page.
    "axes.middleware.AxesMiddleware",
]

# Every page's scripts, styles and images come from this server's static files, its
# sockets and fetches go back to it, and no other site may frame it (docker/Caddyfile
# sends the same to what Django does not serve). Scripts get their data from
# json_script or data attributes, never inline code; styles are static files too.
HRC_CONTENT_SECURITY_POLICY: dict[str, list[str]] = {
    "default-src": ["'self'"],
    "script-src": ["'self'"],
    "style-src": ["'self'"],
    # data: for the small icons that stylesheets embed (Swagger UI's, the admin's).
    "img-src": ["'self'", "data:"],
    # 'self' covers the tablets' and supervisors' WebSockets to this host (ws: and wss:).
    "connect-src": ["'self'"],
    "object-src": ["'none'"],
    "base-uri": ["'self'"],
    "form-action": ["'self'"],
    "frame-ancestors": ["'none'"],
}

ROOT_URLCONF = "hrc.urls"
WSGI_APPLICATION = "hrc.wsgi.application"
ASGI_APPLICATION = "hrc.asgi.application"

TEMPLATES = [
    {
        "BACKEND": "django.template.backends.django.DjangoTemplates",
        "DIRS": [BASE_DIR / "templates"],
        "APP_DIRS": True,
        "OPTIONS": {
            "context_processors": [
                "django.template.context_processors.request",
                "django.contrib.auth.context_processors.auth",
                "django.contrib.messages.context_processors.messages",
                # The header: each role's places, the organisation and its switcher.
                "hrc.navigation.navigation",
            ],
        },
    },
]

DATABASE_URL = env_url("DATABASE_URL", {"postgres", "postgresql", "sqlite"})
if DATABASE_URL:
    DATABASES = {"default": dj_database_url.parse(DATABASE_URL, conn_health_checks=True)}
    if DATABASES["default"]["ENGINE"] == "django.db.backends.postgresql":
        # A pool per process, not persistent connections: under ASGI each request runs
        # on a thread of its own, whose connection would be a new PostgreSQL session
        # per request (its cost: bench/README.md). With the health checks on, the
        # pool checks a connection as it is taken: one that a database restart broke
        # is replaced, not handed out.
        options = DATABASES["default"].setdefault("OPTIONS", {})
        # No statement may hold a connection longer than this, whatever a request asks for:
        # the pool has few connections, and one stuck query per request would drain it.
        timeout_ms = int(float(env_str("HRC_DB_STATEMENT_TIMEOUT") or 30) * 1000)
        options["options"] = f"-c statement_timeout={timeout_ms}"
        # Parameters bound by the server, not quoted into the SQL text by Python. Statements
        # are not prepared (Django's default, prepare_threshold None): preparing the hot
        # path's gained nothing measurable, and their generic plans doubled PostgreSQL's
        # CPU per case (bench/README.md, "Prepared statements").
        options["server_side_binding"] = True
        options["pool"] = {
            "min_size": 1,
            "max_size": int(env_str("HRC_DB_POOL_SIZE") or 10),
            # How long a request waits for a free connection before it answers 503.
            "timeout": float(env_str("HRC_DB_POOL_TIMEOUT") or 10),
        }
else:
    # The embedded default: one file under var/, created by `migrate`. A fresh clone has no
    # var/ yet, and SQLite does not make folders: without this `migrate` could not open it.
    VAR_DIR.mkdir(parents=True, exist_ok=True)
    DATABASES = {
        "default": {"ENGINE": "django.db.backends.sqlite3", "NAME": str(VAR_DIR / "hrc.sqlite3")}
    }
if DATABASES["default"]["ENGINE"] == "django.db.backends.sqlite3":
    # SQLite has one writer at a time and no row locks (select_for_update is a no-op).
    # IMMEDIATE takes the write lock when a transaction begins, so every transaction that
    # would lock rows on PostgreSQL runs alone, and none fails half-way when a second
    # writer upgrades its read lock (the "database is locked" of a DEFERRED begin). WAL lets
    # readers (pages, the tablets' snapshots) go on beside the writer; a writer that finds
    # the lock taken waits up to `timeout` seconds for it instead of failing at once.
    DATABASES["default"].setdefault("OPTIONS", {}).update(
        {
            "transaction_mode": "IMMEDIATE",
            "timeout": 30,
            "init_command": "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;",
        }
    )
DEFAULT_AUTO_FIELD = "django.db.models.BigAutoField"

REDIS_URL = env_url("REDIS_URL", {"redis", "rediss"})
if REDIS_URL:
    CHANNEL_LAYERS = {
        "default": {
            "BACKEND": "channels_redis.core.RedisChannelLayer",
            # A consumer waits for its next message in a blocking pop of 5 s (channels_redis);
            # redis-py's default 5 s socket timeout would end an idle tablet's socket with
            # a 1011 every few seconds. A longer one still notices a dead Redis.
            "CONFIG": {"hosts": [{"address": REDIS_URL, "socket_timeout": 30}]},
        }
    }
    CELERY_BROKER_URL = REDIS_URL
    CELERY_TASK_ALWAYS_EAGER = False
else:
    # Embedded substitutes: one process, no broker. Good for a demo, not a plant.
    CHANNEL_LAYERS = {"default": {"BACKEND": "channels.layers.InMemoryChannelLayer"}}
    CELERY_BROKER_URL = "memory://"
    CELERY_TASK_ALWAYS_EAGER = True
# Tests and the benchmark give each run its own queue on a shared broker.
CELERY_TASK_DEFAULT_QUEUE = env_str("HRC_CELERY_QUEUE") or "celery"
CELERY_TASK_ACKS_LATE = True
CELERY_WORKER_PREFETCH_MULTIPLIER = 1
# A request must not hang on a broker that is down: the row is the truth and
# the sweeper re-sends what was lost, so give up on a send quickly.
CELERY_TASK_PUBLISH_RETRY_POLICY = {
    "max_retries": 2,
    "interval_start": 0,
    "interval_step": 0.2,
    "interval_max": 0.5,
}
CELERY_BROKER_CONNECTION_RETRY_ON_STARTUP = True
# Celery's Django fix-up closes every database connection before and after each
# task, and in a prefork child the whole pool with them, unless this is set: a
# new PostgreSQL session for every step, a few ms of two processes' CPU. Set,
# it does so only every this many tasks; between, hrc.celery gives the
# connection back to the pool around each task as Django does around each request.
CELERY_DB_REUSE_MAX = 10_000
CELERY_WORKER_HIJACK_ROOT_LOGGER = False

LOGGING = {
    "version": 1,
    "disable_existing_loggers": False,
    "filters": {"publish_chatter": {"()": "hrc.logfilters.PublishChatterToDebug"}},
    "loggers": {"asyncua.common.subscription": {"filters": ["publish_chatter"]}},
}

AUTHENTICATION_BACKENDS = [
    # First: refuses a locked-out address before any password is compared.
    "hrc.signin.LockoutBackend",
    "django.contrib.auth.backends.ModelBackend",
]
AXES_FAILURE_LIMIT = int(env_str("HRC_LOGIN_FAILURE_LIMIT") or 10)
AXES_LOCKOUT_PARAMETERS = ["ip_address"]
AXES_COOLOFF_TIME = "hrc.signin.cool_off"
AXES_ENABLE_ACCESS_FAILURE_LOG = True  # the lockouts that lengthen the next cool-off
AXES_RESET_ON_SUCCESS = False
AXES_LOCKOUT_TEMPLATE = (
    "registration/locked_out.html"  # one known password must not reset the count for others
)
# Behind a reverse proxy (Caddy) the client's address is the proxies' last hop in
# X-Forwarded-For; without one, that header is the client's own word and is ignored.
HRC_PROXY_COUNT = int(env_str("HRC_PROXY_COUNT") or 0)
AXES_IPWARE_PROXY_COUNT = HRC_PROXY_COUNT or None
AXES_IPWARE_META_PRECEDENCE_ORDER = (
    ["HTTP_X_FORWARDED_FOR", "REMOTE_ADDR"] if HRC_PROXY_COUNT else ["REMOTE_ADDR"]
)
# API keys (hrc.organisations.models.ApiToken) last this many hours.
HRC_API_TOKEN_HOURS = float(env_str("HRC_API_TOKEN_HOURS") or 24 * 7)

AUTH_PASSWORD_VALIDATORS = [
    {"NAME": "django.contrib.auth.password_validation.UserAttributeSimilarityValidator"},
    {"NAME": "django.contrib.auth.password_validation.MinimumLengthValidator"},
    {"NAME": "django.contrib.auth.password_validation.CommonPasswordValidator"},
    {"NAME": "django.contrib.auth.password_validation.NumericPasswordValidator"},
]

LANGUAGE_CODE = "en-us"
TIME_ZONE = "UTC"
USE_I18N = True
USE_TZ = True

STATIC_URL = "static/"
STATIC_ROOT = BASE_DIR / "staticfiles"
# The editor and tablet bundles that `make install` builds from frontend/src.
STATICFILES_DIRS = [BASE_DIR / "frontend" / "dist"]
LOGIN_URL = "/accounts/login/"
# The start page sends each role on: operators to their tablet.
LOGIN_REDIRECT_URL = "home"
LOGOUT_REDIRECT_URL = "/accounts/login/"

# A pattern document is small; anything near this is a mistake or an attack.
DATA_UPLOAD_MAX_MEMORY_SIZE = 2 * 1024 * 1024

REST_FRAMEWORK = {
    # Token first: a machine without valid credentials gets 401 with
    # `WWW-Authenticate: Token`, which tells an integrator what to send.
    "DEFAULT_AUTHENTICATION_CLASSES": [
        "hrc.api.authentication.ApiTokenAuthentication",
        "rest_framework.authentication.SessionAuthentication",
    ],
    # Size- and depth-limited JSON everywhere, so no view can forget it.
    "DEFAULT_PARSER_CLASSES": ["hrc.api.parsers.LimitedJSONParser"],
    "DEFAULT_PERMISSION_CLASSES": ["rest_framework.permissions.IsAuthenticated"],
    "DEFAULT_SCHEMA_CLASS": "drf_spectacular.openapi.AutoSchema",
    "DEFAULT_PAGINATION_CLASS": "hrc.api.pagination.LimitOffset",
    "PAGE_SIZE": 50,
    "EXCEPTION_HANDLER": "hrc.api.exceptions.exception_handler",
}

SPECTACULAR_SETTINGS = {
    "TITLE": "hrc API",
    "DESCRIPTION": "Human–robot collaboration patterns: model, check, publish and run.",
    "VERSION": "1",
    "SERVE_INCLUDE_SCHEMA": False,
    # From the project's static files, never a CDN: a plant's network may have no way out.
    "SWAGGER_UI_DIST": "SIDECAR",
    "SWAGGER_UI_FAVICON_HREF": "SIDECAR",
    "REDOC_DIST": "SIDECAR",
    # Swagger UI would send the schema to validator.swagger.io for its badge.
    "SWAGGER_UI_SETTINGS": {"deepLinking": True, "validatorUrl": None},
}

# Cobot gateways and drivers. Certificates and trust lists (hrc_gateway.pki);
# keep this directory out of backups that leave the plant.
HRC_PKI_DIR = Path(env_str("HRC_PKI_DIR") or VAR_DIR / "pki")
# The simulator's controller state, so a simulated cobot survives a gateway restart.
HRC_SIM_STATE_DIR = Path(env_str("HRC_SIM_STATE_DIR") or VAR_DIR / "cobots")
# The networks cobot endpoints may be on (comma-separated CIDRs, e.g. 10.20.0.0/16); an endpoint
# elsewhere is refused at registration and never connected to. Unset: no restriction.
HRC_COBOT_NETWORKS = env_networks("HRC_COBOT_NETWORKS")
# The key the cobots' credentials secrets are encrypted with (hrc.cobots.secrets); unset, one is
# derived from SECRET_KEY. Set it apart to rotate SECRET_KEY without losing the secrets.
HRC_SECRETS_KEY = env_str("HRC_SECRETS_KEY") or ""

# Running cases (hrc.cases.jobs). Seconds unless named otherwise.
# The sweeper finds expired leases and jobs whose message the broker lost.
HRC_SWEEP_SECONDS = float(env_str("HRC_SWEEP_SECONDS") or 2.0)
# A leased job's lock lasts its timeout plus this; then the sweeper takes it back.
HRC_JOB_LEASE_MARGIN = float(env_str("HRC_JOB_LEASE_MARGIN") or 30.0)
# The first automatic retry waits this long, each next one twice as long.
HRC_RETRY_BACKOFF = float(env_str("HRC_RETRY_BACKOFF") or 1.0)
# How far down a cobot's queue a free cobot looks for a job whose task may start.
HRC_QUEUE_LOOKAHEAD = 20
# A worker that finishes a step drives its cobot's next one itself while its task is younger
# than this, then hands the next one to the workers (the other cobots' doorbells get a turn).
HRC_CHAIN_SECONDS = float(env_str("HRC_CHAIN_SECONDS") or 0.5)
# Without a broker (the embedded demo), jobs run on a thread pool in the web process.
HRC_INLINE_TASKS = not REDIS_URL

CELERY_BEAT_SCHEDULE = {
    "sweep-jobs": {"task": "hrc.cases.tasks.sweep", "schedule": HRC_SWEEP_SECONDS},
    "purge-messages": {"task": "hrc.cases.tasks.purge_messages", "schedule": 600.0},
}

# Checks of patterns (hrc.patterns.checking). A check in a request decides soundness
# within this many seconds and markings (about 1 kB each), publishing within the larger
# pair; each organisation runs at most HRC_ENGINE_SLOTS engine requests at once.
HRC_CHECK_SECONDS = float(env_str("HRC_CHECK_SECONDS") or 2.0)
HRC_CHECK_MARKINGS = int(env_str("HRC_CHECK_MARKINGS") or 100_000)
HRC_PUBLISH_CHECK_SECONDS = float(env_str("HRC_PUBLISH_CHECK_SECONDS") or 30.0)
HRC_PUBLISH_CHECK_MARKINGS = int(env_str("HRC_PUBLISH_CHECK_MARKINGS") or 200_000)
HRC_ENGINE_SLOTS = int(env_str("HRC_ENGINE_SLOTS") or 2)
# Processes per web process that run the checks (hrc.patterns.checking), off its threads.
HRC_ENGINE_WORKERS = int(env_str("HRC_ENGINE_WORKERS") or 2)
