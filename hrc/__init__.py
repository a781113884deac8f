"""hrc: human–robot collaboration patterns, checked formally and run on the shop floor."""
