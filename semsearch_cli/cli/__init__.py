"""The ``semsearch`` command line (typer): parse, call :mod:`semsearch_cli.api`, print. One module
per feature, each thin over the API: runs (run, sweeps), reports (report, presence, record),
verify (verify, export), ros, info (validate, scenarios, init, schema, show, version, episodes,
planners), bench, generate and imports; common.py holds the app, the consoles and the options they
share, entry.py the ``--version`` callback and :func:`main`."""

from .common import app
from . import runs, reports, verify, ros, info, bench, generate, imports, llm, entry  # noqa: F401  (each registers its commands, in the help's order)
from .entry import main

__all__ = ["app", "main"]
