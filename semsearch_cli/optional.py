"""Optional third-party packages, imported where they are first used rather than where they are
named: nothing at import time of the CLI or of ``semsearch_cli`` needs an extra (a fresh ``pip
install .`` starts), and the Dask executor's ``dask`` and ``distributed`` (half a second to import)
cost nothing to a command that runs on the process pool.

``lazy_module(name, extra)`` looks for the top-level package only (``importlib.util.find_spec`` of
a top-level name imports nothing; of a dotted name it imports the parents, and raises when they
are absent). It returns None when that package is not installed, else a stand-in whose first
attribute access imports ``name``; should that import fail (the package is there but too old to
hold ``name``), it raises :class:`MissingExtra`, which names the extra to install."""

from __future__ import annotations

import importlib
import importlib.util
import sys
from types import ModuleType

from .errors import MissingExtra


def installed(name: str) -> bool:
    """Whether the top-level package of ``name`` is installed, found without importing anything."""
    top = name.partition(".")[0]
    if top in sys.modules:
        return sys.modules[top] is not None
    try:
        return importlib.util.find_spec(top) is not None
    except (ImportError, ValueError):  # a module in sys.modules without a spec, a broken finder
        return False


class _Deferred(ModuleType):
    """``name``, imported at the first attribute access (then held; attribute look-ups go to it)."""

    def __init__(self, name: str, extra: str):
        super().__init__(name)
        self.__dict__["_extra"] = extra
        self.__dict__["_module"] = None

    def __getattr__(self, attr: str):
        module = self.__dict__["_module"]
        if module is None:
            try:
                module = importlib.import_module(self.__name__)
            except ImportError as exc:
                raise MissingExtra(f"semsearch's use of {self.__name__}", self.__dict__["_extra"],
                                   f"{type(exc).__name__}: {exc}") from None
            self.__dict__["_module"] = module
        return getattr(module, attr)


def lazy_module(name: str, extra: str) -> ModuleType | None:
    """The installed package (or sub-module) ``name`` of the ``extra`` extra, imported at its first
    attribute access; None when its top-level package is not installed."""
    if name in sys.modules:
        return sys.modules[name]
    if not installed(name):
        return None
    return _Deferred(name, extra)
