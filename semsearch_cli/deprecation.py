"""Deprecations: a public name, scenario key or row column that changes keeps working for at least
one minor release, with a DeprecationWarning that names its replacement and the releases (since,
until). Each is listed in CHANGELOG.md under "Deprecated", and under "Removed" when it goes."""

from __future__ import annotations

import warnings


def warn(what: str, instead: str, *, since: str, until: str, stacklevel: int = 3) -> None:
    """A DeprecationWarning: ``what`` is deprecated since ``since`` and goes in ``until``; use ``instead``."""
    warnings.warn(f"{what} is deprecated since semsearch {since} and will be removed in {until}: {instead}",
                  DeprecationWarning, stacklevel=stacklevel)
