"""The repository's root, where `manage.py` is and the commands run."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
