"""Organisations, their members' roles and teams: the wall every other app's data sits behind."""
