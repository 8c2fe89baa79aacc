"""The registry of report sections: each kind of search registers, from its own module of this
package, how its rows become part of the report (tables, figures, a replay), what `semsearch run`
prints when it finishes, and how `semsearch show` draws its scenario."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Section:
    """One kind's part of the report.

    ``section(doc, parts, out, formats, replay, notes)`` adds the kind's tables and figures to the
    document; ``console(runs) -> [(title, table)]`` the tables printed after a run;
    ``show(loaded, out)`` draws a scenario; ``replays``: whether ``section`` re-simulates a run
    for an animation (``--replay``)."""

    kind: str
    section: Callable
    console: Callable
    show: Callable
    replays: bool = False


SECTIONS: dict[str, Section] = {}


def register_section(section: Section) -> Section:
    """Add a kind's report section (once per kind)."""
    if not isinstance(section, Section):
        raise TypeError(f"a report section must be a Section, not {type(section).__name__}")
    if section.kind in SECTIONS:
        raise ValueError(f"a report section for kind {section.kind!r} is already registered")
    SECTIONS[section.kind] = section
    return section


def replaying() -> list[str]:
    """The kinds whose section re-simulates a run."""
    return [k for k, s in SECTIONS.items() if s.replays]
