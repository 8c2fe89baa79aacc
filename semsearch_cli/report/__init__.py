"""Reports: tables, statistics, plots (the only place that imports matplotlib) and one document
with a section per kind of search."""
