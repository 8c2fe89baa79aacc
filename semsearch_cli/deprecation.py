"""Deprecated names: a renamed public name keeps working for at least one minor release, with a
DeprecationWarning that names its replacement (a module's ``__getattr__`` calls
:func:`alias`). Each is listed in CHANGELOG.md under "Deprecated"."""

from __future__ import annotations

import warnings


def warn(what: str, instead: str, since: str = "0.2.0", until: str = "0.3.0", stacklevel: int = 3) -> None:
    """A DeprecationWarning: ``what`` is deprecated since ``since`` and goes in ``until``; use ``instead``."""
    warnings.warn(f"{what} is deprecated since semsearch {since} and will be removed in {until}: {instead}",
                  DeprecationWarning, stacklevel=stacklevel)


def alias(module: str, name: str, table: dict):
    """The object a deprecated ``name`` of ``module`` stands for (``table``: old name -> (new name,
    object)), with a DeprecationWarning naming the new one; AttributeError for any other name."""
    if name not in table:
        raise AttributeError(f"module {module!r} has no attribute {name!r}")
    new, obj = table[name]
    warn(f"{module}.{name}", f"use {new}", stacklevel=4)
    return obj
