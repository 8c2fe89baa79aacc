"""Reports: tables, statistics, plots (the only place that imports matplotlib) and one document
with a section per kind of search. Each kind's module registers its section (:mod:`.sections`);
:mod:`.build`, which assembles the document, imports them all."""
