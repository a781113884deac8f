"""Background jobs of the cobots app: none yet; driver commands and state polling will live here."""
