"""What the tests and the bench share: waiting, and the programs they start."""
