"""What the tests and the benchmark share: waiting (polling), the processes they start (workers, Redis), paths."""
