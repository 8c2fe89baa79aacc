"""Which scenario fields enter the fingerprint (the hash a results folder resumes by).

The fields of semsearch 0.3.0's own kinds (:data:`FINGERPRINTED`, dotted paths; ``[]`` an element
of a list, ``{}`` a value of a mapping) always enter, as they always did, so every fingerprint
made before this rule is what it was. A field added since enters only when a scenario sets it away
from its default: adding a field with a default moves no fingerprint and orphans no results
folder, while a scenario that uses the new field gets a fingerprint of its own. A field of a kind
another package adds follows the same rule: at its default, it does not enter. So the default of a
field outside the list is part of the format: changing it means adding the field to the list
(which moves every fingerprint, as a changed default must); ``tests/test_fingerprint.py`` pins the
fields added since 0.3.0 for that reason. (A new field whose default names a file counts that file
by name only, at its default.)

:func:`schema_paths` gives the paths of the kinds registered now; ``tests/test_fingerprint.py``
checks that every path of :data:`FINGERPRINTED` is still among them (a field is removed only after
a deprecation) and that a new one moves no fingerprint.
"""

from __future__ import annotations

import functools
import types
import typing

from pydantic import BaseModel

from .scenario import KINDS

# The fields of semsearch 0.3.0's own kinds (doors, chain, objects, indirect); frozen: a field
# added later is not listed here (it enters a fingerprint only away from its default).
FINGERPRINTED = frozenset("""
belief belief.density_delta belief.density_radius belief.himm_dec belief.himm_inc belief.himm_max belief.min_reads
belief.occupied_threshold belief.visited_radius
chains chains[].name chains[].object_planner chains[].record chains[].stages chains[].stages[].door chains[].stages[].hour
chains[].stages[].object chains[].truth
door_camera door_camera.fov door_camera.p_misread door_camera.p_read door_camera.range
doors doors[].facing doors[].number doors[].x doors[].y duplicates
episodes episodes.clearance episodes.corridor_width episodes.file episodes.given episodes.given[].goal episodes.given[].heading
episodes.given[].x episodes.given[].y episodes.max_distance episodes.min_distance episodes.seed episodes.shared episodes.starts
episodes.where
experiment experiment.base_seed experiment.max_distance experiment.max_steps experiment.out experiment.run_time_limit
experiment.seeds goals
indirect indirect.ablation indirect.camera indirect.camera.detection indirect.camera.diameters indirect.camera.fps
indirect.camera.height indirect.camera.hfov indirect.camera.min_depth indirect.camera.model indirect.camera.occlusion
indirect.camera.pitch indirect.camera.secondary_range indirect.camera.table indirect.camera.vfov indirect.coarse
indirect.count_once indirect.learned indirect.learned.rooms indirect.learned.seed indirect.masks indirect.masks.gap
indirect.masks.u1 indirect.masks.u2 indirect.masks.u3 indirect.noise indirect.noise.false_positive indirect.noise.position_sd
indirect.objects_block indirect.p_outside indirect.relations indirect.replan_every indirect.resolution indirect.robot
indirect.robot.radius indirect.robot.speed indirect.robot.turn_rate indirect.rooms indirect.rooms.count
indirect.rooms.obstacles indirect.rooms.seed indirect.rooms.size indirect.target indirect.time_limit indirect.view_scales
kind
laser laser.beams laser.fov laser.noise_std laser.range
map map.clean map.image map.origin map.resolution map.ros
name
navigation navigation.navigator navigation.replan navigation.replan_every
objects objects.camera objects.camera.classes objects.camera.classes{}.fov objects.camera.classes{}.p_detect
objects.camera.classes{}.p_detect.angles objects.camera.classes{}.p_detect.distances objects.camera.classes{}.p_detect.p
objects.camera.classes{}.range objects.camera.fov objects.camera.p_detect objects.camera.p_detect.angles
objects.camera.p_detect.distances objects.camera.p_detect.p objects.camera.range objects.cases objects.cases[].name
objects.cases[].record objects.cases[].requests objects.cases[].requests[].at objects.cases[].requests[].cls
objects.cases[].requests[].hour objects.cases[].truth objects.fixed objects.places objects.places[].facing
objects.places[].name objects.places[].room objects.places[].x objects.places[].y objects.recording_hours objects.requests
objects.requests[].at objects.requests[].cls objects.requests[].hour objects.route objects.timelines
planners planners[].module planners[].name
robot robot.radius robot.step
start start.heading start.x start.y
""".split())


def _models_in(annotation) -> list[tuple[str, type[BaseModel]]]:
    """The models a field's annotation holds, each with the path step to it ("" the field itself,
    "[]" an element of a list, "{}" a value of a mapping)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [("", annotation)]
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Annotated:
        return _models_in(args[0])
    if origin in (typing.Union, types.UnionType):
        return [m for a in args for m in _models_in(a)]
    if origin in (list, tuple, set, frozenset):
        return [("[]" + s, m) for a in args if a is not Ellipsis for s, m in _models_in(a)]
    if origin is dict and len(args) == 2:
        return [("{}" + s, m) for s, m in _models_in(args[1])]
    return []


def schema_fields(built_in: bool = True) -> dict:
    """Every field of every kind's model, nested models' fields included, by dotted path: its
    pydantic ``FieldInfo`` (the first kind's, where kinds share a path; ``built_in``: semsearch's
    own kinds only)."""
    out: dict = {}
    seen: set = set()

    def walk(model: type[BaseModel], prefix: str) -> None:
        for name, f in model.model_fields.items():
            path = prefix + name
            out.setdefault(path, f)
            for step, sub in _models_in(f.annotation):
                if (path + step, sub) not in seen:
                    seen.add((path + step, sub))
                    walk(sub, path + step + ".")

    for cls in KINDS.values():
        if not built_in or cls.__module__.startswith("semsearch_cli."):
            walk(cls, "")
    return out


def schema_paths(built_in: bool = True) -> set[str]:
    """The dotted paths of :func:`schema_fields`."""
    return set(schema_fields(built_in))


_ABSENT = object()


@functools.lru_cache(maxsize=8)
def _parents(known: frozenset) -> tuple[frozenset, frozenset]:
    """(the paths with fields under them, the paths that are mappings of models) among ``known``."""
    nested, mappings = set(), set()
    for f in known:
        for i, ch in enumerate(f):
            if ch in ".[{":
                nested.add(f[:i])
                if ch == "{":
                    mappings.add(f[:i])
    return frozenset(nested), frozenset(mappings)


def drop_new_defaults(doc, set_away, known: frozenset = FINGERPRINTED, path: str = ""):
    """``doc`` (a scenario's canonical form, as JSON) without the fields outside ``known`` that
    ``set_away`` (the same scenario dumped without its defaults) does not hold: the fields added
    since :data:`FINGERPRINTED` that the scenario leaves at their defaults. A mapping's keys are
    data, not fields: the fields of its values are ``path{}.field``."""
    if isinstance(doc, list):
        away = set_away if isinstance(set_away, list) and len(set_away) == len(doc) else [_ABSENT] * len(doc)
        return [drop_new_defaults(v, a, known, path + "[]") for v, a in zip(doc, away)]
    if not isinstance(doc, dict):
        return doc
    nested, mappings = _parents(known)
    if path in mappings:  # a mapping of models: its keys are data, its values models at path{}
        return {k: drop_new_defaults(v, set_away.get(k, _ABSENT) if isinstance(set_away, dict) else _ABSENT, known, path + "{}")
                for k, v in doc.items()}
    out = {}
    for k, v in doc.items():
        away = set_away.get(k, _ABSENT) if isinstance(set_away, dict) else _ABSENT
        sub = f"{path}.{k}" if path else k
        if sub not in known and away is _ABSENT:
            continue
        # a field of its own (a number, a list or a mapping of plain values) enters whole
        out[k] = v if sub in known and sub not in nested else drop_new_defaults(v, away, known, sub)
    return out
