"""The hostile catalogue of the surfaces the last release added (issue 52), one module per surface:
``tests/hostile_robot_surface.py`` (a robot's messages, damaged bags, ``ros live``'s flags),
``tests/hostile_bench_surface.py`` (verify, the board, bench run / hash / list) and
``tests/hostile_llm_surface.py`` (secrets in addresses, planner parameters, the llm planner).

Each module gives ``CLASSES`` and ``build_cases(root)``; :func:`build_cases` here is them all, each
case's category prefixed by its surface (``robot: live``). ``tests/test_hostile_surfaces.py`` runs
the fast ones in CI; ``benchmarks/hostile.py --catalogue surfaces`` runs every case as a process.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from . import hostile_bench_surface, hostile_llm_surface, hostile_robot_surface

SURFACES = {"robot": hostile_robot_surface, "bench": hostile_bench_surface, "llm": hostile_llm_surface}
CLASSES = tuple(f"{name}: {cls}" for name, mod in SURFACES.items() for cls in mod.CLASSES)


def build_cases(root: Path) -> list:
    """Every case of every surface's catalogue, its files under ``root/<surface>``."""
    return [replace(case, category=f"{name}: {case.category}")
            for name, mod in SURFACES.items() for case in mod.build_cases(Path(root) / name)]
