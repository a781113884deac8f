# hrc — every target installs what it needs first. `make` lists them.
SHELL := /bin/bash
PY := .venv/bin/python
PIP := .venv/bin/pip -q --disable-pip-version-check
STAMP := .venv/.installed
BENCH_STAMP := .venv/.bench-installed

.DEFAULT_GOAL := help
.PHONY: help install demo test lint bench lock clean

# Browser tests drive Debian's chromium; Playwright never downloads a browser.
CHROMIUM := /usr/bin/chromium

help:  ## list the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk -F':.*## ' '{printf "  make %-8s %s\n", $$1, $$2}'

# The editor and the tablets' scripts: npm's locked toolchain, bundled by
# esbuild into frontend/dist/, which Django serves as static files.
NPM_STAMP := frontend/node_modules/.installed
FRONTEND_BUILD := frontend/dist/.built
$(NPM_STAMP): frontend/package-lock.json
	cd frontend && npm ci --no-audit --no-fund --loglevel=error
	@touch $@

$(FRONTEND_BUILD): $(NPM_STAMP) frontend/build.mjs $(shell find frontend/src -type f 2>/dev/null)
	cd frontend && npm run --silent build
	@mkdir -p frontend/dist && touch $@

$(STAMP): requirements/lock.txt
	@test -x $(PY) || python3 -m venv .venv
	$(PIP) install -r requirements/lock.txt 2>&1 | grep -v "is ignored: it is neither" || true
	@$(PY) -c "import django, rest_framework, channels, celery, asyncua" 
	@touch $@

install: $(STAMP) $(FRONTEND_BUILD)  ## create .venv, install the locked Python and npm dependencies, build the frontend (idempotent)

demo: install  ## migrate, load the demo people and examples, start two simulated cobots and the server on 127.0.0.1:8000 (Ctrl-C stops all)
	@mkdir -p var  # the embedded SQLite database lives here when DATABASE_URL is unset
	@# hrc/demo/management/commands/demo.py: prints the passwords once; e.g. DEMO_ARGS="--port 8001"
	$(PY) manage.py demo $(DEMO_ARGS)

$(CHROMIUM):
	apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null

# The tests take the bench's dependencies too: the XES export is read back by pm4py.
test: install $(BENCH_STAMP) $(CHROMIUM)  ## run the whole test suite (PostgreSQL and Redis on 127.0.0.1, chromium for the browser tests)
	@if [ -d frontend/test ]; then cd frontend && npx vitest run; fi
	$(PY) -m pytest -n 2 -p no:cacheprovider

lint: install  ## ruff, mypy, tsc, ESLint, the import contracts, the docs build
	.venv/bin/ruff check .
	.venv/bin/ruff format --check .
	.venv/bin/mypy hrc hrc_gateway tests bench
	.venv/bin/lint-imports
	cd frontend && npx tsc --noEmit
	cd frontend && npx eslint .
	NO_MKDOCS_2_WARNING=1 .venv/bin/mkdocs build --strict --quiet  # docs/ into site/ (ignored)

$(BENCH_STAMP): $(STAMP) requirements/bench-lock.txt
	$(PIP) install -r requirements/bench-lock.txt 2>&1 | grep -v "is ignored: it is neither" || true
	@touch $@

bench: $(BENCH_STAMP)  ## soundness check vs Woflan, corpus import, cobot handshake vs raw OPC UA, case runtime, use cases, the prediction against real runs; JSON in bench/results/
	$(PY) -m bench.run
	$(PY) -m bench.corpus
	$(PY) -m bench.handshake
	$(PY) -m bench.runtime
	$(PY) -m bench.editor
	$(PY) -m bench.live
	$(PY) -m bench.use_cases
	$(PY) -m bench.prediction

lock:  ## re-resolve requirements/*.in into the lock files
	python3 -m venv /tmp/hrc-lock && /tmp/hrc-lock/bin/pip -q install uv
	/tmp/hrc-lock/bin/uv pip compile --python-version 3.11 requirements/dev.in -o requirements/lock.txt
	/tmp/hrc-lock/bin/uv pip compile --python-version 3.11 requirements/bench.in -c requirements/lock.txt -o requirements/bench-lock.txt

clean:  ## remove the venv, caches and the embedded database
	rm -rf .venv var frontend/node_modules frontend/dist .mypy_cache .ruff_cache .pytest_cache .hypothesis
