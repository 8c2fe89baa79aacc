"""Optional third-party packages, imported where they are first used rather than where they are
named: the Dask executor's ``dask`` and ``distributed`` (half a second to import) cost nothing to a
command that runs on the process pool."""

from __future__ import annotations

import importlib.util
import sys
from types import ModuleType


def lazy_module(name: str) -> ModuleType | None:
    """The installed package ``name`` as a module whose code runs at its first attribute access
    (:class:`importlib.util.LazyLoader`); None when it is not installed."""
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.find_spec(name)
    if spec is None:
        return None
    spec.loader = importlib.util.LazyLoader(spec.loader)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
