"""Indirect-search planners (Loncomilla et al. 2018, Sections 3.3 and 4.5): the paper's
eleven methods, each registered under the paper's name, so rows read ``UIS``, ``ISCG-PN-SM``, ...

- ``UIS``: local search (Eqs. 33-34) on the map of A's non-detections alone.
- ``ISC-{PN,OP}-{HM,SM}``: local search on the map that also folds in the secondary objects,
  by convolution with hard (HM) or soft (SM) masks; PN uses their detections and their
  non-detections at every frame, OP their detections only.
- ``ISCG-...``: the same maps, global search by regions (Eq. 35).
- ``ISUP`` (Aydemir et al.): A's non-detections; when a secondary object is detected in the
  current frame, 500 particles are drawn around it from its relation, weighted by the relation
  and A's map; those at or above half the best weight are kept, and the robot goes to the
  reachable pose whose view cone holds the most of them. It re-plans at once on such a frame
  (it is reactive: it has no memory of secondary objects).
- ``AOSEOOR`` (Elfring et al., Algorithm 3, Eq. 36): no probability map. Among the secondary
  objects seen and not yet visited, the one with the highest EU = p(o | A) + w / atan(dist) is the
  target when its EU reaches ``threshold``; the robot goes to a pose ``approach`` m from it, facing
  it, and marks it visited on arrival. Otherwise it searches at random: by default it goes to a
  random reachable free pose of the room (``random_search: waypoint``); ``walk``, our earlier
  reading, makes a short random move within one re-plan's horizon.
  p(o | A) is the share of Table 2 in which o is seen with A at all, 1 - C^VF.

Local search: ``n_poses`` random sequences of a rotation, a translation and a rotation that the
robot can finish before the next re-plan (N = 3, as the paper prints under Eq. 34; 50 was our
earlier choice), collision-free;
the one whose final view cone holds the most probability of A (Eq. 33; V of Eq. 34 is the camera's
cone at the view scale, on the grid, ignoring obstacles). Global search: regions of
``region`` x ``region`` cells; P_reg the sum of the map in a region; its centroid moved to the
nearest cell the robot can stand on, the region dropped if that leaves it; EU = P_reg + w /
atan(dist), dist the path length (m) from the robot. The paper drops a region "when the robot is
near the centroid of a region, the region is observed"; we read "observed": a region is visited
once the robot has passed within ``visit_radius`` of its centroid, and (``visited: seen``, the
default) also once the centroid has been in the camera's view cone of A. (Near alone leaves
regions the camera has already swept alive, and the distance term, 0.34 for a region 0.3 m away
against 0.0025 for the probability of an average region, then sends the robot region by region
over ground it has seen.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field
from scipy import ndimage

from ..belief.indirect import IndirectBelief
from ..geometry import GridFrame
from ..sensors.indirect import ConeTemplates
from .base import Planner, register_planner


@dataclass
class IndirectContext:
    """What an indirect-search planner may look at.

    belief : the probability map of A (already up to date); frame : its grid; stand : (H, W) bool,
    cells the robot's centre may occupy; x, y, heading : the robot's pose (m, rad); t : s since
    the search began; view_scale : m; cones : the view cone of A at that scale, for
    :meth:`ConeTemplates.mass`; speed (m/s), turn_rate (rad/s), horizon (s until the next
    re-plan); rng : the run's generator; seen : class -> (x, y) m where each secondary object was
    last detected; latest : the classes detected in the latest frame; trail : (n, 3) the poses
    (x, y m, heading rad) since the last plan; sees : (poses, xs, ys) -> (n, m) bool, whether each
    pose had each point in its view cone of A; path_length : (x, y) -> m along the free cells from
    the robot (lazy);
    relations : class -> the mixed relation mask over every offset (ISUP's particles);
    cooccurrence : class -> p(o | A), the share of Table 2 in which o is seen with A (AOSEOOR);
    target : the target's class (A); room : the room's name; room_size : (width, height) m of the
    room, whose south-west corner is the frame's origin; time_limit : s the search may take.
    """

    belief: IndirectBelief | None
    frame: GridFrame
    stand: np.ndarray
    x: float
    y: float
    heading: float
    t: float
    view_scale: float
    cones: ConeTemplates
    speed: float
    turn_rate: float
    horizon: float
    rng: np.random.Generator
    seen: dict = field(default_factory=dict)
    latest: set = field(default_factory=set)
    trail: np.ndarray | None = None
    sees: Any = None
    path_length: Any = None
    relations: dict = field(default_factory=dict)
    cooccurrence: dict = field(default_factory=dict)
    target: str = ""
    room: str = ""
    room_size: tuple = (0.0, 0.0)
    time_limit: float = math.inf


@dataclass
class Goal:
    """Where to go: a position (m), the heading to turn to on arrival (rad, or None), the numbers
    behind the choice."""

    x: float
    y: float
    heading: float | None
    info: dict = field(default_factory=dict)


HEADINGS = np.radians(np.arange(0, 360, 45))  # the 8 headings of a lattice pose (0 east, 45, ..., 315 deg)


@dataclass(frozen=True)
class Lattice:
    """Poses over a room: points every ``step`` m from ``step / 2`` (``xs`` by ``ys``, point ``k
    = i + len(xs) j`` at ``(xs[i], ys[j])``), each with the 8 :data:`HEADINGS`; pose ``8 k + h``.
    ``standable``: (N,) whether the robot can stand at each point (inside the grid, on a cell of
    ``stand``)."""

    xs: np.ndarray
    ys: np.ndarray
    points: np.ndarray
    standable: np.ndarray
    step: float

    @classmethod
    def over(cls, frame: GridFrame, stand: np.ndarray, size: tuple, step: float) -> "Lattice":
        xs, ys = np.arange(step / 2, size[0], step), np.arange(step / 2, size[1], step)
        gx, gy = np.meshgrid(xs, ys)
        r, c = frame.to_index(gx.ravel(), gy.ravel())
        H, W = stand.shape
        inside = (r >= 0) & (r < H) & (c >= 0) & (c < W)
        ok = np.zeros(gx.size, bool)
        ok[inside] = stand[r[inside], c[inside]]
        return cls(xs, ys, np.stack([gx.ravel(), gy.ravel()], axis=1), ok, step)

    @property
    def n(self) -> int:
        return len(self.points)

    def mask(self) -> np.ndarray:
        """(8 N,) bool: every heading of the points the robot can stand on."""
        return np.repeat(self.standable, 8)

    def pose(self, action: int) -> tuple[float, float, float]:
        """Pose ``action`` = 8 k + h as (x, y m, heading rad); a point the robot cannot stand on
        is taken as the nearest that it can."""
        k, h = divmod(int(action), 8)
        if not self.standable[k]:
            d = np.hypot(*(self.points - self.points[k]).T)
            d[~self.standable] = np.inf
            k = int(np.argmin(d))
        return float(self.points[k, 0]), float(self.points[k, 1]), float(HEADINGS[h])


class IndirectPlanner(Planner):
    """Base of the indirect-search planners. The class says how the robot's map is built: which
    masks (``masks``: hard, soft or None for no secondary objects) and whether the secondary
    objects' non-detections count (``negative``)."""

    task: ClassVar[str] = "indirect"
    masks: ClassVar[str | None] = None
    negative: ClassVar[bool] = False
    uses_map: ClassVar[bool] = True
    replan_on_detection: ClassVar[bool] = False
    run_attributes: ClassVar[tuple] = ("masks", "negative", "uses_map", "replan_on_detection")  # a replay keeps them

    def plan(self, ctx: IndirectContext) -> Goal:  # pragma: no cover
        raise NotImplementedError


class LocalParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    n_poses: int = Field(3, ge=1, le=5000, description="N of Eq. 34: candidate poses per re-plan (the paper prints N = 3)")


class GlobalParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    w: float = Field(0.1, ge=0.0, description="weight of distance in Eq. 35")
    region: int = Field(5, ge=1, le=50, description="cells a side of a region")
    visited: Literal["seen", "near"] = Field("seen", description="a region is visited once the robot passed within "
                                             "visit_radius of its centroid (near) or, with seen, also once the "
                                             "centroid has been in the camera's view of A")
    visit_radius: float = Field(0.3, gt=0.0, description="m (ours)")


def local_poses(ctx: IndirectContext, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``n`` random rotation-translation-rotation sequences finished within the horizon, and
    whether each is collision-free: (x, y, final heading, ok)."""
    rng, T, v, w = ctx.rng, ctx.horizon, ctx.speed, ctx.turn_rate
    rot1 = rng.uniform(-math.pi, math.pi, n)
    left = np.maximum(T - np.abs(rot1) / w, 0.0)
    d = rng.uniform(0.0, 1.0, n) * v * left
    left2 = np.maximum(left - d / v, 0.0)
    rot2 = rng.uniform(-1.0, 1.0, n) * np.minimum(math.pi, w * left2)
    h1 = ctx.heading + rot1
    xs, ys = ctx.x + d * np.cos(h1), ctx.y + d * np.sin(h1)
    fr = ctx.frame
    steps = np.linspace(0.0, 1.0, max(2, int(math.ceil(v * T / fr.res)) + 1))
    px = ctx.x + (xs - ctx.x)[:, None] * steps[None]
    py = ctx.y + (ys - ctx.y)[:, None] * steps[None]
    r, c = fr.to_index(px, py)
    H, W = ctx.stand.shape
    inside = (r >= 0) & (r < H) & (c >= 0) & (c < W)
    ok = inside.all(axis=1)
    ok[ok] = ctx.stand[r[ok], c[ok]].all(axis=1)
    return xs, ys, h1 + rot2, ok


def best_view(ctx: IndirectContext, p: np.ndarray, n: int) -> tuple[Goal, float]:
    """Eqs. 33-34: of ``n`` random reachable poses, the one whose view cone holds the most of
    ``p`` (the robot's own pose, turning on the spot, is always among them)."""
    xs, ys, hs, ok = local_poses(ctx, n)
    r, c = ctx.frame.to_index(xs, ys)
    score = np.full(n, -np.inf)
    if ok.any():
        score[ok] = ctx.cones.mass(p, r[ok], c[ok], hs[ok])
    k = int(np.argmax(score))
    if not np.isfinite(score[k]):  # nowhere to go: turn on the spot
        h = ctx.heading + ctx.rng.uniform(-1.0, 1.0) * min(math.pi, ctx.turn_rate * ctx.horizon)
        return Goal(ctx.x, ctx.y, float(h), {"mode": "turn"}), 0.0
    return Goal(float(xs[k]), float(ys[k]), float(hs[k]), {"mode": "local", "mass": round(float(score[k]), 5)}), float(score[k])


WAYPOINT_TRIES = 20


def random_waypoint(ctx: IndirectContext) -> Goal:
    """A pose drawn uniformly over the room's free cells the robot can stand on and reach, with a
    uniform heading (a turn on the spot when none of ``WAYPOINT_TRIES`` draws is reachable)."""
    rr, cc = np.nonzero(ctx.stand)
    if len(rr):
        for _ in range(WAYPOINT_TRIES):
            k = int(ctx.rng.integers(len(rr)))
            x, y = ctx.frame.to_world(rr[k], cc[k])
            if np.isfinite(ctx.path_length(np.array([x]), np.array([y]))[0]):
                return Goal(float(x), float(y), float(ctx.rng.uniform(-math.pi, math.pi)), {"mode": "random"})
    return Goal(ctx.x, ctx.y, float(ctx.heading + math.pi / 2), {"mode": "turn"})


class LocalSearch(IndirectPlanner):
    """Eqs. 33-34 on the robot's map."""

    Params = LocalParams

    def plan(self, ctx):
        return best_view(ctx, ctx.belief.p, self.params.n_poses)[0]


class GlobalSearch(IndirectPlanner):
    """Eq. 35 over regions of the robot's map."""

    Params = GlobalParams

    def __init__(self, params):
        super().__init__(params)
        self._regions = None  # (rows, cols) of the corrected centroids, (k,) region index, alive mask

    def _setup(self, ctx):
        k = self.params.region
        H, W = ctx.stand.shape
        nr, nc = -(-H // k), -(-W // k)
        # nearest standable cell of every cell
        _, (ir, ic) = ndimage.distance_transform_edt(~ctx.stand, return_indices=True)
        rr, cc = np.meshgrid(np.arange(nr), np.arange(nc), indexing="ij")
        cr = np.minimum(rr * k + k // 2, H - 1).ravel()
        ccol = np.minimum(cc * k + k // 2, W - 1).ravel()
        tr, tc = ir[cr, ccol], ic[cr, ccol]
        keep = (tr // k == rr.ravel()) & (tc // k == cc.ravel()) & ctx.stand[tr, tc]
        self._valid = keep
        self._regions = (tr, tc, keep.copy())
        self._grid = (nr, nc, k)

    def plan(self, ctx):
        if self._regions is None:
            self._setup(ctx)
        tr, tc, alive = self._regions
        nr, nc, k = self._grid
        fr = ctx.frame
        cx, cy = fr.to_world(tr, tc)
        if ctx.trail is not None and len(ctx.trail):
            idx = np.flatnonzero(alive)
            done = (np.hypot(cx[idx][None] - ctx.trail[:, :1], cy[idx][None] - ctx.trail[:, 1:2])
                    <= self.params.visit_radius).any(axis=0)
            if self.params.visited == "seen":
                done |= ctx.sees(ctx.trail, cx[idx], cy[idx]).any(axis=0)
            alive[idx[done]] = False
        if not alive.any():  # every region visited: start over
            alive[:] = self._valid
        H, W = ctx.stand.shape
        p = np.zeros((nr * k, nc * k))
        p[:H, :W] = ctx.belief.p
        preg = p.reshape(nr, k, nc, k).sum(axis=(1, 3)).ravel()
        dist = ctx.path_length(cx, cy)
        with np.errstate(divide="ignore"):
            eu = preg + self.params.w / np.arctan(np.maximum(dist, 1e-3))
        eu[~alive | ~np.isfinite(dist)] = -np.inf
        j = int(np.argmax(eu))
        if not np.isfinite(eu[j]):
            return best_view(ctx, ctx.belief.p, 20)[0]
        return Goal(float(cx[j]), float(cy[j]), None, {"mode": "region", "region": j, "p_reg": round(float(preg[j]), 5),
                                                       "dist_m": round(float(dist[j]), 2), "eu": round(float(eu[j]), 5)})


def _register(name: str, base: type, masks: str | None, negative: bool, rank: int) -> type:
    cls = type(name.replace("-", "_"), (base,), {"masks": masks, "negative": negative, "rank": rank,
                                                 "replay": name == "ISCG-PN-SM",  # the paper's best reading
                                                 "__doc__": f"{name} (Loncomilla et al. 2018, Section 4.5)"})
    return register_planner(name)(cls)


# ranks: the order of the paper's Table 3 (UIS, ISUP, AOSEOOR, then ISC and ISCG, hard masks first)
_register("UIS", LocalSearch, None, False, 0)
for _s, (_search, _base) in enumerate((("ISC", LocalSearch), ("ISCG", GlobalSearch))):
    for _i, _info in enumerate(("PN", "OP")):
        for _k, (_m, _kind) in enumerate((("HM", "hard"), ("SM", "soft"))):
            _register(f"{_search}-{_info}-{_m}", _base, _kind, _info == "PN", 3 + 4 * _s + 2 * _k + _i)


class IsupParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    n_poses: int = Field(3, ge=1, le=5000, description="N of Eq. 34 when it searches locally (the paper prints N = 3)")
    particles: int = Field(500, ge=1, le=100000)
    keep: float = Field(0.5, gt=0.0, le=1.0, description="keep particles at or above this share of the best weight")


@register_planner("ISUP")
class Isup(IndirectPlanner):
    """Aydemir et al.: particles around a secondary object seen in the current frame."""

    rank = 1

    Params = IsupParams
    masks = None  # the map holds A's non-detections only; the particles come from the soft relation
    negative = False
    replan_on_detection = True

    def plan(self, ctx):
        if not ctx.latest:
            return best_view(ctx, ctx.belief.p, self.params.n_poses)[0]
        fr, H, W = ctx.frame, ctx.frame.height, ctx.frame.width
        counts = np.zeros((H, W))
        for cls in sorted(ctx.latest):
            R = ctx.relations[cls]
            br, bc = (int(v) for v in fr.to_index(*ctx.seen[cls]))
            ci, cj = H - 1, W - 1
            rel = R[ci - br:ci - br + H, cj - bc:cj - bc + W]
            q = rel.ravel() / rel.sum()
            idx = ctx.rng.choice(H * W, size=self.params.particles, p=q)
            w = rel.ravel()[idx] * ctx.belief.p.ravel()[idx]
            good = idx[w >= self.params.keep * w.max()] if w.max() > 0 else idx
            np.add.at(counts.ravel(), good, 1.0)
        goal, _ = best_view(ctx, counts, self.params.n_poses)
        goal.info.update(mode="particles", particles=int(counts.sum()))
        return goal


class AoseoorParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    w: float = Field(0.1, ge=0.0, description="weight of distance in Eq. 36")
    threshold: float = Field(0.5, ge=0.0, description="EU needed to go to an object (ours: the paper gives none)")
    approach: float = Field(0.8, gt=0.0, description="m from the object to look at it from (ours)")
    random_search: Literal["waypoint", "walk"] = Field(
        "waypoint", description="waypoint: go to a random reachable free pose of the room (Elfring et al.'s random "
        "search); walk: a short random move within one re-plan's horizon (our earlier reading)")
    n_poses: int = Field(50, ge=1, le=5000, description="random moves tried per re-plan (random_search: walk)")


@register_planner("AOSEOOR")
class Aoseoor(IndirectPlanner):
    """Elfring et al., Algorithm 3 with Eq. 36: go to the most promising secondary object seen."""

    rank = 2

    Params = AoseoorParams
    masks = None
    negative = False
    uses_map = False

    def __init__(self, params):
        super().__init__(params)
        self.dead: set[str] = set()
        self.target: str | None = None

    def plan(self, ctx):
        if self.target is not None:
            tx, ty = ctx.seen[self.target]
            if math.hypot(ctx.x - tx, ctx.y - ty) <= self.params.approach + 0.15:
                self.dead.add(self.target)  # reached: it did not lead to A (else the search had ended)
            self.target = None
        cands = [c for c in sorted(ctx.seen) if c not in self.dead]
        if cands:
            xy = np.array([ctx.seen[c] for c in cands])
            dist = ctx.path_length(xy[:, 0], xy[:, 1])
            p = np.array([ctx.cooccurrence.get(c, 0.0) for c in cands])
            eu = p + self.params.w / np.arctan(np.maximum(dist, 1e-3))
            j = int(np.argmax(eu))
            if eu[j] >= self.params.threshold and np.isfinite(dist[j]):
                tx, ty = xy[j]
                a = math.atan2(ctx.y - ty, ctx.x - tx)
                gx, gy = tx + self.params.approach * math.cos(a), ty + self.params.approach * math.sin(a)
                r, c = ctx.frame.to_index(gx, gy)
                if 0 <= r < ctx.stand.shape[0] and 0 <= c < ctx.stand.shape[1] and ctx.stand[r, c]:
                    self.target = cands[j]
                    return Goal(float(gx), float(gy), float(a + math.pi), {"mode": "object", "object": cands[j],
                                                                           "eu": round(float(eu[j]), 4)})
        if self.params.random_search == "waypoint":
            return random_waypoint(ctx)
        # random walk: a short random move that the robot can finish before the next re-plan
        xs, ys, hs, ok = local_poses(ctx, self.params.n_poses)
        k = int(np.flatnonzero(ok)[0]) if ok.any() else None
        if k is None:
            return Goal(ctx.x, ctx.y, float(ctx.heading + math.pi / 2), {"mode": "turn"})
        return Goal(float(xs[k]), float(ys[k]), float(hs[k]), {"mode": "random"})
