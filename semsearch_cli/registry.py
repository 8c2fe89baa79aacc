"""One kind of registry for everything that registers itself by name: kinds of scenario, tasks,
planners, navigators, executors and report sections. A registry refuses a second entry under a
name (naming the module that took it) and an entry of the wrong type."""

from __future__ import annotations

from typing import Any


class Registry(dict):
    """``name -> entry``, filled by :meth:`add` (or the :meth:`register` decorator). ``base``: a
    class every entry must subclass or be an instance of (None: any callable); ``what`` names an
    entry in messages; with ``names``, each entry gets its name as its ``name`` attribute."""

    def __init__(self, what: str, base: type | None = None, names: bool = False):
        super().__init__()
        self.what, self.base, self.names = what, base, names

    def add(self, name: str, entry: Any) -> Any:
        if self.base is not None and not (isinstance(entry, self.base) or isinstance(entry, type) and issubclass(entry, self.base)):
            raise TypeError(f"{self.what} {name!r}: {entry!r} is not a subclass of {self.base.__name__}")
        if self.base is None and not callable(entry):
            raise TypeError(f"{self.what} {name!r}: {entry!r} is not callable")
        if not name:
            raise ValueError(f"a {self.what} needs a name")
        if name in self:
            raise ValueError(f"{self.what} {name!r} is already registered (by {getattr(self[name], '__module__', '?')}); "
                             "choose another name")
        if self.names:
            entry.name = name  # the class knows the name it answers to
        self[name] = entry
        return entry

    def register(self, name: str):
        """Decorator: :meth:`add` the decorated class or function under ``name``."""
        return lambda entry: self.add(name, entry)
