"""Background jobs of the patterns app: none; checks run in the request within a budget
(hrc.patterns.checking says why)."""
