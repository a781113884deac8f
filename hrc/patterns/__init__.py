"""Collaboration pattern models: editable drafts and their immutable published versions."""
