"""What the tests and the benchmark share: processes they start (workers, Redis) and paths."""
