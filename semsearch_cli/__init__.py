"""semsearch: object-search planners in a fast 2D occupancy-grid simulator."""

__version__ = "0.1.0"
