"""Cobots: the robots an organisation runs, how to reach them and where their credentials come from."""
