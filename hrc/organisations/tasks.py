"""Background jobs of the organisations app: none yet (invitations and syncs would live here)."""
