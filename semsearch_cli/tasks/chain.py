"""Chained searches (placeholder, written next)."""
