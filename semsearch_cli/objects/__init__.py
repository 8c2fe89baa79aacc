"""Object search over time (thesis chapter 5)."""
