"""The demo: `manage.py demo` (what `make demo` runs) and `manage.py load_demo`.

`organisation` provisions the demo organisation and its personas, `library`
publishes the example patterns into it, `runner` starts and stops the
processes of a demo (simulated gateways, worker, web server).
"""
