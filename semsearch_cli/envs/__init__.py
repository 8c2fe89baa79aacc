"""Gymnasium environments over semsearch's scenarios (``pip install 'semsearch[gym]'``).

Importing this package registers, under the ``semsearch/`` namespace:

- ``semsearch/DoorSearch-v1`` (any door scenario: ``scenario="configs/hotel.yaml"``), and the
  shipped buildings ``DoorSearch-Hotel-v1``, ``-Normal-v1``, ``-Inverse-v1``, ``-KTH-v1``: the
  llm planner's targets and text; each also as ``-v0`` (deprecated since 0.4.0, removed in 0.5.0);
- ``semsearch/DoorSearch-Generated-v1`` (and ``-v0``): a building generated at each reset from
  ``layout`` and ``numbering`` (``semsearch generate building``), one of ``buildings`` seeds;
- ``semsearch/ObjectSearch-v0`` (``ObjectSearch-Office-v0``) and ``semsearch/IndirectSearch-v0``
  (``IndirectSearch-Quick-v0``).

See docs/environments.md for the spaces, the reward and the equivalence with ``semsearch run``.
"""

from __future__ import annotations

from gymnasium.envs.registration import register, registry

from .doors import DoorSearchEnv
from .generated import GeneratedDoorSearchEnv
from .indirect import IndirectSearchEnv
from .objects import ObjectSearchEnv
from .policies import PlannerPolicy

ENVS = (DoorSearchEnv, ObjectSearchEnv, IndirectSearchEnv)  # each: semsearch/<name>-v<n> and its shipped buildings
VERSIONS = {"DoorSearch": (0, 1)}  # the versions of an environment with more than v0, each a ``version`` argument


def register_envs() -> list[str]:
    """Register every environment id (once); returns the ids."""
    ids = {}
    for env, name in (*((e, e.env_name) for e in ENVS), (GeneratedDoorSearchEnv, "DoorSearch-Generated")):
        versions = VERSIONS.get(env.env_name)
        for v in versions or (0,):
            version = {"version": v} if versions else {}
            ids[f"semsearch/{name}-v{v}"] = (env, version)
            for building, config in (env.shipped.items() if env is not GeneratedDoorSearchEnv else ()):
                ids[f"semsearch/{name}-{building}-v{v}"] = (env, {"scenario": f"shipped:{config}", **version})
    for env_id, (entry, kwargs) in ids.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry, kwargs=kwargs)
    return list(ids)


ENV_IDS = register_envs()

__all__ = ["DoorSearchEnv", "ENV_IDS", "GeneratedDoorSearchEnv", "IndirectSearchEnv", "ObjectSearchEnv", "PlannerPolicy",
           "register_envs"]
