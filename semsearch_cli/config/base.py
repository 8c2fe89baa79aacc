"""The sections every scenario shares: map, start, door signs, planners, robot, sensors, belief,
navigation, experiment. Lengths are metres, angles degrees; every model forbids unknown
keys, so a misspelt key is an error naming the field, and refuses NaN and infinity, so a number
is always a number. Sizes have upper bounds (the Limits table in docs/usage.md) so that no value makes an
array too big for memory or a loop that never ends."""

from __future__ import annotations

import re
import unicodedata
from typing import Annotated, Any, Literal, Union, get_args

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, field_validator, model_validator

# upper bounds shared by the sections (m): far beyond any building, short of an array that fills memory
MAX_RANGE = 50.0  # a sensor's range
MAX_RADIUS = 20.0  # a kernel or window radius
MAX_COORD = 1e6  # a coordinate or a distance
MAX_SEEDS = 1_000_000  # runs per goal and planner variant

Coord = Annotated[float, Field(ge=-MAX_COORD, le=MAX_COORD)]
Angle = Annotated[float, Field(ge=-3600.0, le=3600.0, description="degrees")]


MAX_LABEL = 64  # characters of a sign's label (a goal, a room): longer is not a label but a file name too long
MAX_LABEL_DIGITS = 18  # digits of a whole-number label: it is kept as a 64-bit integer
_WHOLE = re.compile(r"[-+]?[0-9]+", re.ASCII)
_SPREADSHEET = re.compile(r"[-+]?[0-9]+\.0+", re.ASCII)  # 304.0: a whole number a spreadsheet wrote as a float


def sign_label(value):
    """A sign's label in its one canonical form, wherever it was written (a scenario, a doors or
    episodes CSV, ``--goal``, an importer): a whole number (``148``, ``"148"`` in YAML or a CSV,
    the float ``148.0``) is an int, anything else (``K202``, ``24D``, ``2.14``, ``NA``) stripped
    text, its spaces (a spreadsheet's non-breaking space) plain. A goal is then matched to its sign
    however either was written: ``goals: ["148"]`` finds the sign ``148`` of a CSV. A CSV column
    a spreadsheet wrote as floats (``304.0``) is read by :func:`label_column`.

    Bounds (a ``ValueError`` naming them): at most ``MAX_LABEL`` (64) characters, no control
    character, not empty; a whole number has at most ``MAX_LABEL_DIGITS`` (18) digits. Digits are
    ASCII ``0-9`` only: ``30²`` or ``٣٠`` is a text label with no number, never the number 30."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (float, np.floating)):
        if not np.isfinite(value):
            raise ValueError(f"a label must be a finite number or text, got {value!r}")
        value = int(value) if float(value).is_integer() else repr(float(value))
    if isinstance(value, (int, np.integer)):
        if len(str(abs(int(value)))) > MAX_LABEL_DIGITS:
            raise ValueError(f"a whole-number label has at most {MAX_LABEL_DIGITS} digits, got {len(str(abs(int(value))))}")
        return int(value)
    text = str(value)
    if len(text) > 4 * MAX_LABEL:  # before any work on it: a 60,000-character label is refused at once
        raise ValueError(f"a label has at most {MAX_LABEL} characters, got {len(text)}")
    text = "".join(" " if unicodedata.category(ch) == "Zs" else ch for ch in text).strip()
    if not text:
        raise ValueError("a label cannot be empty")
    if len(text) > MAX_LABEL:
        raise ValueError(f"a label has at most {MAX_LABEL} characters, got {len(text)}: {text[:20]}...")
    if any(unicodedata.category(ch) in ("Cc", "Cf", "Zl", "Zp") for ch in text):
        raise ValueError(f"a label holds no tab, line break or other control character, got {text!r}")
    if _WHOLE.fullmatch(text):
        return sign_label(int(text))
    return text


def label_column(values: list) -> list:
    """The labels of one CSV column (a doors file's numbers, an episodes file's goals), each by
    :func:`sign_label`; when every one of them is a whole number written as a float (``304.0``,
    ``101.00``: a spreadsheet's column of numbers), they are those numbers. A column that mixes
    ``3.0`` with ``K202`` or ``2.14`` is text (``3.0`` may be floor 3, room 0)."""
    texts = [str(v).strip() for v in values]
    if texts and all(_SPREADSHEET.fullmatch(t) for t in texts):
        return [sign_label(int(t.split(".")[0])) for t in texts]
    return [sign_label(v) for v in values]


_NUMBER = re.compile(r"\s*[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?\s*", re.ASCII)


def number_text(text) -> float:
    """A number written in a CSV or a text file, read as a person writes numbers: ``1_5`` and
    ``١٥``, which Python's ``float`` reads as 15, raise ``ValueError``; so does anything not a
    number. ``inf`` and ``nan`` are read as such (the caller refuses them where they are wrong)."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return float(text)
    if not isinstance(text, str) or not (_NUMBER.fullmatch(text) or text.strip().lstrip("+-").lower() in ("inf", "nan", "infinity")):
        raise ValueError(f"not a number: {text!r}")
    return float(text)


Label = Annotated[Union[int, str], BeforeValidator(sign_label)]


_ODD_NUMBER = re.compile(r"_|^\s*[-+]?0[0-9]", re.ASCII)  # 1_5 (Python reads 15), 010 (YAML 1.1 reads 8)


def _takes(annotation, types) -> bool:
    """Whether a field's type admits ``types`` (itself, or inside a union, a list or Annotated)."""
    types = types if isinstance(types, tuple) else (types,)
    return annotation in types or any(_takes(a, types) for a in get_args(annotation))


class Strict(BaseModel):
    """A section: unknown keys, NaN and infinity refused, and a yes/no/true/false refused where a
    number belongs (pydantic reads True as 1: ``starts: yes`` would draw one start)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @field_validator("*", mode="before")
    @classmethod
    def _numbers_as_written(cls, value, info):
        ann = cls.model_fields[info.field_name].annotation
        if isinstance(value, dict) or not _takes(ann, (int, float)):
            return value  # a section (checked by its own model), or a field of no numbers
        for leaf in value if isinstance(value, (list, tuple)) else (value,):  # a number or a list of numbers
            if isinstance(leaf, bool) and not _takes(ann, bool):
                raise ValueError("expected a number or text, not yes/no (a YAML boolean: yes, no, on, off, true, false)")
            if isinstance(leaf, str) and not _takes(ann, str) and _ODD_NUMBER.search(leaf):
                raise ValueError(f"expected a number as written in decimal, got {leaf!r} (no underscores, no leading zeros)")
        return value


class MapSpec(Strict):
    """A PNG of our own (``image`` with ``resolution`` and ``origin``), or a ROS map (``ros``: the
    map_server YAML, which carries its own resolution and origin)."""

    image: str | None = Field(None, description="PNG: dark (<100) wall, light (>=200) free, gray between = outside")
    ros: str | None = Field(None, description="a ROS map_server / map_saver YAML (PGM or PNG image)")
    resolution: float = Field(0.1, ge=0.005, le=1.0, description="m/cell")
    origin: tuple[Coord, Coord] = Field((0.0, 0.0), description="world (x, y) m of the image's bottom-left corner")
    clean: bool = Field(False, description="clean a SLAM map: free space the robot cannot reach from the start, and "
                        "laser fans narrower than the robot, become outside")

    @model_validator(mode="after")
    def _one_source(self):
        if (self.image is None) == (self.ros is None):
            raise ValueError("give either image (a PNG) or ros (a map_server YAML)")
        if self.ros is not None and self.model_fields_set & {"resolution", "origin"}:
            raise ValueError("a ROS map carries its own resolution and origin; remove them here")
        return self


class StartSpec(Strict):
    x: Coord
    y: Coord
    heading: Union[Angle, Literal["random"]] = Field("random", description="degrees, or random")


class DoorSpec(Strict):
    number: Label
    x: Coord
    y: Coord
    facing: Angle = Field(description="degrees, the direction the sign faces")


class PlannerSpec(BaseModel):
    """``{name: ..., <parameter>: value | [values]}``; parameters are checked by the planner."""

    model_config = ConfigDict(extra="allow", frozen=True)
    name: str
    module: str | None = Field(None, description="a Python file (relative to the scenario) that registers this planner")

    def params(self) -> dict[str, Any]:
        return dict(self.model_extra or {})


class RobotSpec(Strict):
    radius: float = Field(0.25, gt=0.0, le=5.0, description="m, disk robot")
    step: float = Field(0.1, ge=0.01, le=1.0, description="m travelled per simulation step")


class LaserSpec(Strict):
    fov: float = Field(180.0, gt=0.0, le=360.0, description="degrees")
    beams: int = Field(181, ge=2, le=2000)
    range: float = Field(10.0, gt=0.0, le=MAX_RANGE, description="m")
    noise_std: float = Field(0.0, ge=0.0, le=10.0, description="m, Gaussian range noise")


class DoorCameraSpec(Strict):
    fov: float = Field(60.0, gt=0.0, le=180.0, description="degrees, each of the left and right cameras")
    range: float = Field(3.0, gt=0.0, le=MAX_RANGE, description="m")
    p_read: float = Field(0.95, ge=0.0, le=1.0, description="probability a visible sign is read")
    p_misread: float = Field(0.0, ge=0.0, le=1.0, description="probability a read replaces one digit")


class BeliefSpec(Strict):
    visited_radius: float = Field(1.2, gt=0.0, le=MAX_RADIUS, description="m, kernel of the visited region")
    density_radius: float = Field(2.4, gt=0.0, le=MAX_RADIUS, description="m, uniform kernel radius r of Eq. 4.2 (Manhattan)")
    # at least 0.05 m^2: the densest kernel (a 20 m Manhattan radius, 800 m^2) then has 16,000
    # classes, which the belief keeps in 16 bits
    density_delta: float = Field(2.5, ge=0.05, le=1e4, description="m^2, delta of Eq. 4.4")
    min_reads: int = Field(3, ge=1, description="reads before a sign feeds the planner's factors")
    himm_inc: int = Field(3, ge=1, le=15)
    himm_dec: int = Field(1, ge=1, le=15)
    himm_max: int = Field(15, ge=1, le=255)
    occupied_threshold: int = Field(3, ge=1, description="certainty at or above which a seen cell is occupied")


class NavigationSpec(Strict):
    navigator: str = Field("geodesic", pattern=r"^[A-Za-z0-9_\-]+$",
                           description="a registered navigator: geodesic (the cheapest path) or harmonic (the thesis' BVP)")
    replan_every: float = Field(1.0, gt=0.0, le=MAX_COORD, description="m travelled between periodic re-plans")
    replan: Literal["periodic", "events"] = Field(
        "periodic", description="door search: periodic re-plans every replan_every m (the thesis' tables), or only on "
        "what changes the decision or the path (the path used up, a sign read, a free cell of the map lost)")


class EpisodeSpec(Strict):
    """One start/goal problem given by hand: the goal (a door number, a request label, a chain's
    name; for indirect search, the room's name, the view scales being the goals) and the start."""

    goal: Label
    x: Coord
    y: Coord
    heading: Union[Angle, Literal["random"]] = Field("random", description="degrees, or random (drawn per repeat)")


MAX_EPISODES = 100_000


class EpisodesSpec(Strict):
    """The episode set: start/goal problems, each run ``experiment.seeds`` times (the repeats).

    Give one of ``starts`` (drawn), ``list`` (by hand) or ``file`` (a CSV written by ``semsearch
    episodes``). Without an ``episodes`` section a scenario has one episode per goal, from its
    ``start`` (the thesis' fixed starts)."""

    starts: int | None = Field(None, ge=1, le=MAX_EPISODES,
                               description="starts drawn per goal (indirect search: per room) from the reachable free space")
    seed: int = Field(0, ge=0, le=2**31, description="the draw's seed (the same seed, the same set)")
    where: Literal["anywhere", "corridors", "rooms"] = Field(
        "anywhere", description="draw only in corridors (free space narrower than corridor_width) or only in rooms (the rest)")
    corridor_width: float = Field(3.0, gt=0.0, le=MAX_RADIUS * 2, description="m, free space narrower than this is corridor")
    clearance: float = Field(0.5, ge=0.0, le=MAX_RADIUS, description="m, least distance from a drawn start to a wall "
                             "(a start hugging a wall can leave the robot unable to plan; door and object maps)")
    min_distance: float = Field(0.0, ge=0.0, le=MAX_COORD, description="m, least geodesic distance from a start to its goal")
    max_distance: float | None = Field(None, gt=0.0, le=MAX_COORD, description="m, greatest geodesic distance to the goal")
    shared: bool = Field(False, description="one set of starts for every goal (each within the distances of every goal)")
    given: list[EpisodeSpec] | None = Field(None, alias="list", description="episodes given by hand")
    file: str | None = Field(None, description="a CSV of episodes (goal, start_x, start_y, start_heading), e.g. from semsearch episodes")

    @model_validator(mode="after")
    def _one_source(self):
        given = [k for k, f in (("starts", "starts"), ("list", "given"), ("file", "file")) if getattr(self, f) is not None]
        if len(given) != 1:
            raise ValueError("give exactly one of starts (drawn), list (by hand) or file (a CSV)"
                             + (f"; got {' and '.join(given)}" if given else ""))
        if self.given is not None and not self.given:
            raise ValueError("list is empty: give at least one episode")
        if self.max_distance is not None and self.max_distance <= self.min_distance:
            raise ValueError(f"max_distance ({self.max_distance:g} m) must exceed min_distance ({self.min_distance:g} m)")
        return self


class ExperimentSpec(Strict):
    seeds: int = Field(10, ge=1, le=MAX_SEEDS, description="repeats of each episode per planner variant (the seed column)")
    base_seed: int = Field(0, ge=0, le=2**31)
    max_distance: float = Field(2000.0, gt=0.0, le=MAX_COORD, description="m, budget per run")
    max_steps: int | None = Field(None, ge=1, le=10**9)
    run_time_limit: float = Field(3600.0, gt=0.0, le=7 * 86400.0, description="s of wall-clock time a run may take; "
                                  "past it the run is recorded as timeout (a planner that hangs) and the batch goes on. "
                                  "Generous: our longest runs take about 2 minutes. Not enforced on Dask workers")
    out: str | None = Field(None, description="output folder (default results/<name>)")


