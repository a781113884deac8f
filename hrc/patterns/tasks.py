"""Background jobs of the patterns app: none; checks are fast enough to run in the request."""
