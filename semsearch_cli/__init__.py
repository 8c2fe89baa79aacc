"""semsearch: object-search planners in a fast 2D occupancy-grid simulator."""

import os

# NumPy asks Linux for transparent huge pages (2 MB) for every array of 4 MB or more, so a search
# that writes a thin band across a map-sized grid makes the whole grid resident: a worker on a map
# of 3.7 M cells peaked at 442 MB with them and 368 MB without, and ran no slower (docs/usage.md,
# "Limits"). NumPy reads this when it is imported, so it is set here, before any of our modules
# import it; a value the user set is kept.
os.environ.setdefault("NUMPY_MADVISE_HUGEPAGE", "0")

__version__ = "0.3.0"
