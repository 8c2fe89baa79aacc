"""The registry of report sections: each kind of search registers, from its own module of this
package, how its rows become part of the report (tables, figures, a replay), what `semsearch run`
prints when it finishes, and how `semsearch show` draws its scenario."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..registry import Registry


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


SECTIONS = Registry("report section", Section)  # kind -> its Section


def register_section(section: Section) -> Section:
    """Add a kind's report section (once per kind)."""
    return SECTIONS.add(getattr(section, "kind", ""), section)


def replaying() -> list[str]:
    """The kinds whose section re-simulates a run."""
    return [k for k, s in SECTIONS.items() if s.replays]
