"""Gymnasium environments over semsearch's scenarios (``pip install 'semsearch[gym]'``).

Importing this package registers, under the ``semsearch/`` namespace:

- ``semsearch/DoorSearch-v0`` (any door scenario: ``scenario="configs/hotel.yaml"``), and the
  shipped buildings ``DoorSearch-Hotel-v0``, ``-Normal-v0``, ``-Inverse-v0``, ``-KTH-v0``;
- ``semsearch/DoorSearch-Generated-v0``: a building generated at each reset from ``layout`` and
  ``numbering`` (``semsearch generate building``), one of ``buildings`` seeds;
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

ENVS = (DoorSearchEnv, ObjectSearchEnv, IndirectSearchEnv)  # each: semsearch/<name>-v0 and its shipped buildings


def register_envs() -> list[str]:
    """Register every environment id (once); returns the ids."""
    ids = {f"semsearch/{env.env_name}-v0": (env, {}) for env in ENVS}
    ids["semsearch/DoorSearch-Generated-v0"] = (GeneratedDoorSearchEnv, {})
    for env in ENVS:
        for building, config in env.shipped.items():
            ids[f"semsearch/{env.env_name}-{building}-v0"] = (env, {"scenario": f"shipped:{config}"})
    for env_id, (entry, kwargs) in ids.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry, kwargs=kwargs)
    return list(ids)


ENV_IDS = register_envs()

__all__ = ["DoorSearchEnv", "ENV_IDS", "GeneratedDoorSearchEnv", "IndirectSearchEnv", "ObjectSearchEnv", "PlannerPolicy",
           "register_envs"]
