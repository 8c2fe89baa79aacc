"""The simulator engine: which behaviour of the simulator made a result.

The engine is the simulator's contract with every row it wrote: its sensing, belief, skeleton,
distances, candidates and navigation, everything that decides where a robot drives. Planners,
scenarios and suites have versions of their own (a planner's code hash, a scenario's fingerprint, a
suite's hash); the engine is the one for what lies under all of them. It changes only with a new
number (never a silent change of rows), and every result carries the number that made it: each
row (``engine``), decisions record, meta.json, language-model transcript and exported bag, and the
scenario fingerprint (from engine 2 on), so rows of two engines never resume, mix or pair.

A result of another engine is read, reported and boarded as before; what replays it (``semsearch
verify``, ``semsearch export``, ``semsearch ros replay``) refuses it, naming the release that
replays it (:func:`refusal`). docs/engines.md says what each engine changed.
"""

from __future__ import annotations

ENGINE = 2

# the releases that run each engine, as pip reads them
RELEASES = {1: "0.2.*", 2: "0.3.*"}


def engine_of(value) -> int:
    """The engine a stored result names: ``value`` as written in a row, a record or a bag (a missing
    or empty value: engine 1, which wrote none); ``ValueError`` when it is not a whole number >= 1."""
    if value is None or (isinstance(value, float) and value != value) or (isinstance(value, str) and value.strip() == ""):
        return 1
    if isinstance(value, bool):
        raise ValueError(f"{value!r} is not an engine number")
    if isinstance(value, float):
        if not value.is_integer():
            raise ValueError(f"{value!r} is not an engine number")
        value = int(value)
    if isinstance(value, str):
        text = value.strip()
        if not text.isascii() or not text.isdigit():
            raise ValueError(f"{value!r} is not an engine number")
        value = int(text)
    if not isinstance(value, int) or value < 1:
        raise ValueError(f"{value!r} is not an engine number")
    return value


def release(engine: int) -> str:
    """``pip install 'semsearch==0.2.*'``: what installs a release that runs ``engine`` (one of
    this release's own engines needs nothing)."""
    if engine == ENGINE:
        return "this release"
    if engine in RELEASES:
        return f"pip install 'semsearch=={RELEASES[engine]}'"
    return f"a newer semsearch, one that runs engine {engine}"


def refusal(engine: int, what: str) -> str | None:
    """The one line that refuses to replay ``what`` (a folder, a record, a bag) of another engine,
    naming the release that replays it; None when ``engine`` is this release's."""
    if engine == ENGINE:
        return None
    return (f"{what} was made by simulator engine {engine} and this semsearch runs engine {ENGINE}, whose runs differ: "
            f"replay it with the release that made it ({release(engine)}); it is read, reported and boarded here as before")
