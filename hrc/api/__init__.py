"""Project-wide API plumbing: the URL root of every app's api/ and the error format."""
