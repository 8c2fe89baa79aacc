"""The chain section of a report (thesis ch. 6): written with the chain task."""
