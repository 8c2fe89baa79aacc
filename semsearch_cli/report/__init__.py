"""Reports: tables, statistics, plots (the only place that imports matplotlib) and one document
with a section per kind of search. Each kind's module registers its section
(:mod:`.sections`); importing this package registers them all."""

from . import doors, objects, chain, indirect  # noqa: F401  (registration side effect)
