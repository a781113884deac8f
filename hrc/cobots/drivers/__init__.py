"""Drivers: how workers and commands talk to a cobot.

`base.py` is the small contract every driver keeps (commands, the step, typed
errors that say whether a retry can help); each driver is a folder on it:
`opcua/` talks to a cobot gateway (hrc_gateway/) over OPC UA.
`runner.py` gives synchronous code (Celery tasks, management commands) one
long-lived driver per cobot per process.
"""
