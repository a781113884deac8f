"""The cobots app's answers to the organisations app's hooks, registered when Django is ready."""

from hrc.cobots import selectors
from hrc.organisations import hooks

# A cell cannot be deleted while a cobot stands in it.
hooks.register_cell_occupants(selectors.cobots_in_cell)
