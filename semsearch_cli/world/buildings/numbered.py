"""Generated numbered buildings: corridor layouts x door-numbering schemes (issue: scenario library).

A building is a set of straight corridors (centre line and width) rasterised into a map where
the corridors are free, their walls are one cell thick and everything else is "outside" (rooms
are closed, as in the authors' maps: the robot searches the corridors and reads the signs on
their walls). Along each corridor wall a door slot lies every ``spacing`` metres; slots where
the wall is missing (a junction) or that are trimmed to reach a sign count keep their number as
a gap, so numbering stays that of a real building.

Layouts (``LAYOUTS``):
  grid    corridors around room blocks, like the thesis' Normal map;
  wings   a long main corridor with perpendicular wings and a loop, like its Hotel;
  angled  corridors at 30 and 120 degrees off a main one, like its KTH floor;
  single  one long corridor;
  hall    an open hall (a lobby: doors around its walls, open ends) with corridors leaving it east,
          west and north.

Numbering schemes (``SCHEMES``):
  odd-even-out  odd numbers on one wall, even on the other, rising with the distance from the
                middle of the building along the corridors (the thesis' Normal);
  odd-even-in   the same, falling with that distance (its Inverse);
  corridor-parity  one parity per corridor on both of its walls, the corridors alternating (odd,
                even, odd, ...; a hundred-block per pair of corridors), numbers rising from the
                corridor's middle outward and alternating between the walls: the authors' Normal
                map (``par_impar_par_impar``, "even odd even odd");
  corridor-parity-in  the same, rising from the corridor's ends toward its middle: their Inverse;
  floor         rising along each corridor, both walls in turn, floor digit first (201, 202, ...);
  blocks        one hundred-block per corridor (101.., 201.., ...), rising along it, with gaps;
  loop          rising along one wall of each corridor to its end and back along the other, floor
                digit first (201, 202, ... along the left wall, then the right): consecutive
                numbers share a wall, so a wall has no parity (as on most KTH floors, docs/bench.md);
  random        a random permutation: the control case where no planner can use the signs.

What real floors add on top of a scheme (:func:`generate_building`'s ``skip``, ``letters``,
``extension`` and ``style``): numbers skipped (a share of the number range without a door, as
rooms wider than a door spacing leave them), a room's doors sharing its number with letter
suffixes (``24a``, ``24b``), a later extension renumbered in a hundred-block of its own, and labels
written with a wing prefix (``K201``) or as floor-dot-room (``2.14``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import yaml

from ...errors import ScenarioError
from ...geometry import GridFrame
from ...kernels.grid import dijkstra
from ..labels import parse_label
from ..scenario_folder import map_image, scenario_dict, write_building
from ..importers.mobilesim import spread_goals

LAYOUTS = ("grid", "wings", "angled", "single", "hall")
SCHEMES = ("odd-even-out", "odd-even-in", "corridor-parity", "corridor-parity-in", "floor", "blocks", "loop", "random")
STYLES = ("plain", "wing", "dot")  # how a number is written: 201, K201 (a wing prefix per corridor), 2.01
WING_LETTERS = "ABCDEFGHJKLMNPRSTUVWXYZ"  # no I, O, Q: read as digits


@dataclass(frozen=True)
class Corridor:
    """A straight corridor: centre line from ``a`` to ``b`` (m) and its width (m)."""

    a: tuple[float, float]
    b: tuple[float, float]
    width: float = 2.0


@dataclass(frozen=True)
class Plan:
    corridors: tuple[Corridor, ...]
    size: tuple[float, float]  # m (width, height)
    start: tuple[float, float]  # m


def scaled(plan: Plan, k: float) -> Plan:
    """The plan stretched ``k`` times in x and y (``k**2`` times the area) with its corridors as
    wide as before: the same building at a larger scale, for costs that should grow with the
    work and not with the map."""
    if k == 1.0:
        return plan
    m = lambda p: (p[0] * k, p[1] * k)  # noqa: E731
    return Plan(tuple(Corridor(m(c.a), m(c.b), c.width) for c in plan.corridors), m(plan.size), m(plan.start))


def layout(name: str, rng: np.random.Generator) -> Plan:
    """The corridors of a layout; small random variations (lengths, wing positions) per seed."""
    j = lambda s: float(rng.uniform(-s, s))  # noqa: E731  (jitter)
    if name == "single":
        L = 60.0 + j(8)
        return Plan((Corridor((2.0, 5.0), (2.0 + L, 5.0)),), (L + 4.0, 10.0), (2.0 + L / 2, 5.0))
    if name == "grid":
        W, H = 50.0 + j(4), 29.0 + j(3)
        ys = [1.5, 1.5 + (H - 1.5) / 3, 1.5 + 2 * (H - 1.5) / 3, H]
        xs = [1.5, 1.5 + (W - 1.5) / 2, W]
        cs = [Corridor((xs[0], y), (xs[-1], y)) for y in ys] + [Corridor((x, ys[0]), (x, ys[-1])) for x in xs]
        return Plan(tuple(cs), (W + 2.5, H + 2.5), (xs[1], ys[-1] - 0.5))
    if name == "wings":
        main_y, L = 50.0, 112.0 + j(6)
        wx = sorted([9.0, 46.0 + j(3), 83.0 + j(3), 9.0 + L])
        cs = [Corridor((wx[0], main_y), (wx[-1], main_y))]
        cs += [Corridor((x, main_y), (x, 6.0 + j(2))) for x in wx]
        lx0, lx1 = 57.0 + j(2), 92.0 + j(2)
        cs += [Corridor((lx0, main_y), (lx0, main_y + 11)), Corridor((lx1, main_y), (lx1, main_y + 11)),
               Corridor((lx0, main_y + 11), (lx1, main_y + 11))]
        cs += [Corridor((wx[1], main_y), (wx[1], main_y + 16))]  # the start stub
        return Plan(tuple(cs), (wx[-1] + 10.0, main_y + 20.0), (wx[1], main_y + 14.0))
    if name == "angled":
        a0, a1 = (3.0, 8.0), (50.0 + j(3), 8.0)
        cs = [Corridor(a0, a1)]
        for x0, ang, length in ((14.0 + j(2), 30.0, 26.0), (34.0 + j(2), 120.0, 24.0)):
            t = np.radians(ang + j(5))
            cs.append(Corridor((x0, 8.0), (x0 + length * np.cos(t), 8.0 + length * np.sin(t))))
        far = cs[1].b
        t = np.radians(120.0 + j(5))
        cs.append(Corridor(far, (far[0] + 14.0 * np.cos(t), far[1] + 14.0 * np.sin(t))))
        xs = [p for c in cs for p in (c.a[0], c.b[0])]
        ys = [p for c in cs for p in (c.a[1], c.b[1])]
        shift = (3.0 - min(xs), 3.0 - min(ys))
        cs = [Corridor((c.a[0] + shift[0], c.a[1] + shift[1]), (c.b[0] + shift[0], c.b[1] + shift[1]), c.width) for c in cs]
        return Plan(tuple(cs), (max(xs) + shift[0] + 3.0, max(ys) + shift[1] + 3.0), (cs[0].a[0] + 1.5, cs[0].a[1]))
    if name == "hall":
        # the hall is a wide corridor: rasterise() extends it by half its depth at both ends,
        # open floor without doors; the corridors start at its walls
        W, D = 16.0 + j(3), 10.0 + j(2)
        east, west, north = 26.0 + j(4), 22.0 + j(4), 18.0 + j(3)
        x0, y = 3.0 + west + D / 2, 3.0 + D / 2 + 1.0
        cs = [Corridor((x0, y), (x0 + W, y), D),
              Corridor((x0 + W + D / 2, y), (x0 + W + D / 2 + east, y)),
              Corridor((x0 - D / 2 - west, y), (x0 - D / 2, y)),
              Corridor((x0 + W / 2, y + D / 2), (x0 + W / 2, y + D / 2 + north))]
        return Plan(tuple(cs), (x0 + W + D / 2 + east + 3.0, y + D / 2 + north + 3.0), (x0 + W / 2, y))
    raise ScenarioError("<command line>", "--layout", f"unknown layout {name!r}; valid: {', '.join(LAYOUTS)}")


def rasterise(plan: Plan, res: float) -> tuple[np.ndarray, GridFrame]:
    """(H, W) uint8 image: corridors 255, their one-cell walls 0, outside gray."""
    W, H = int(np.ceil(plan.size[0] / res)), int(np.ceil(plan.size[1] / res))
    frame = GridFrame(res, 0.0, 0.0, H, W)
    free = np.zeros((H, W), np.uint8)
    for c in plan.corridors:
        a, b = np.array(c.a), np.array(c.b)
        u = (b - a) / np.linalg.norm(b - a)
        n = np.array([-u[1], u[0]])
        h = c.width / 2
        # axis-aligned corridors are extended by half their width to fill the corners they meet;
        # slanted ones start on the centre line of the corridor they branch from
        ea = h if abs(u[0]) < 1e-9 or abs(u[1]) < 1e-9 else 0.0
        pts = [a - u * ea + n * h, b + u * h + n * h, b + u * h - n * h, a - u * ea - n * h]
        r, cc = frame.to_cell(np.array([p[0] for p in pts]), np.array([p[1] for p in pts]))
        cv2.fillPoly(free, [np.stack([cc, r], axis=1).round().astype(np.int32)], 1)
    return map_image(free.astype(bool)), frame


@dataclass
class Slot:
    corridor: int
    side: int  # +1: left of a -> b, -1: right
    t: float  # m along the corridor
    x: float  # m, on the wall face
    y: float
    facing: float  # degrees, into the corridor
    ok: bool  # a wall is there (not a junction)


def door_slots(plan: Plan, img: np.ndarray, frame: GridFrame, spacing: float) -> list[Slot]:
    """Door slots every ``spacing`` m along both walls of each corridor."""
    out = []
    for k, c in enumerate(plan.corridors):
        a, b = np.array(c.a), np.array(c.b)
        L = float(np.linalg.norm(b - a))
        u = (b - a) / L
        n = np.array([-u[1], u[0]])
        H, W = img.shape
        for side in (1, -1):
            for t in np.arange(spacing / 2, L - spacing / 4, spacing):
                centre = a + u * t
                # walk from the centre line toward this wall until the corridor ends
                p, ok = centre, False
                for step in np.arange(0.0, c.width / 2 + 4 * frame.res, frame.res / 2):
                    q = centre + side * n * step
                    r, cc = frame.to_index(*q)
                    if not (0 <= r < H and 0 <= cc < W):
                        break
                    if img[r, cc] != 255:
                        ok = bool(img[r, cc] == 0)  # a wall, not another corridor or outside
                        break
                    p = q
                face = p + side * n * (frame.res / 2)
                facing = float(np.degrees(np.arctan2(-side * n[1], -side * n[0])))
                out.append(Slot(k, side, float(t), round(float(face[0]), 4), round(float(face[1]), 4), round(facing, 2), ok))
    return out


def number_slots(slots: list[Slot], plan: Plan, scheme: str, img: np.ndarray, frame: GridFrame,
                 rng: np.random.Generator, floor: int = 2) -> list[int]:
    """A door number for every slot (gaps included) under ``scheme``."""
    if scheme in ("odd-even-out", "odd-even-in"):
        # distances along the corridors from the middle of the building (its free cell nearest
        # the centre of the plan)
        free = img == 255
        fr_, fc_ = np.nonzero(free)
        mr, mc = frame.to_cell(plan.size[0] / 2, plan.size[1] / 2)
        k = int(np.argmin((fr_ - mr) ** 2 + (fc_ - mc) ** 2))
        r, c = fr_[k], fc_[k]
        _, length, _ = dijkstra(free, np.ones((1, 1), np.float32), np.array([r]), np.array([c]), np.zeros_like(free), 0, np.inf)
        d = []
        for s in slots:
            cor = plan.corridors[s.corridor]
            a, b = np.array(cor.a), np.array(cor.b)
            u = (b - a) / np.linalg.norm(b - a)
            centre = a + u * s.t
            ahead = centre + u * 1.0
            rc0, rc1 = frame.to_index(*centre), frame.to_index(*ahead)
            d0, d1 = length[rc0], length[rc1]
            outward = 1 if (np.isfinite(d1) and np.isfinite(d0) and d1 >= d0) else -1
            d.append((float(d0) if np.isfinite(d0) else 1e9, s.side * outward))
        order = np.argsort([x[0] for x in d], kind="stable")
        if scheme == "odd-even-in":
            order = order[::-1]
        nums = [0] * len(slots)
        nxt = {1: 1, -1: 2}
        for i in order:
            side = d[i][1]
            nums[i] = nxt[side]
            nxt[side] += 2
        return nums
    if scheme in ("corridor-parity", "corridor-parity-in"):
        return corridor_parity(slots, plan, outward=scheme == "corridor-parity")
    if scheme == "floor":
        nums, i = [], 0
        order = sorted(range(len(slots)), key=lambda k: (slots[k].corridor, slots[k].t, -slots[k].side))
        nums = [0] * len(slots)
        for i, k in enumerate(order, start=1):
            nums[k] = floor * 100 + i  # past 99 doors the numbers run on into the next hundred (300, 301, ...)
        return nums
    if scheme == "blocks":
        nums = [0] * len(slots)
        order = sorted(range(len(slots)), key=lambda k: (slots[k].corridor, slots[k].t, -slots[k].side))
        count: dict = {}
        for k in order:
            cor = slots[k].corridor
            count[cor] = count.get(cor, 0) + 1
            nums[k] = 100 * (cor + 1) + count[cor]
        return nums
    if scheme == "loop":
        # up the left wall (side +1) from a to b, back along the right wall from b to a
        order = sorted(range(len(slots)), key=lambda k: (slots[k].corridor, -slots[k].side, slots[k].t * slots[k].side))
        nums = [0] * len(slots)
        for i, k in enumerate(order, start=1):
            nums[k] = floor * 100 + i
        return nums
    if scheme == "random":
        return [int(x) for x in rng.permutation(len(slots)) + 1]
    raise ScenarioError("<command line>", "--numbering", f"unknown numbering scheme {scheme!r}; valid: {', '.join(SCHEMES)}")


def corridor_parity(slots: list[Slot], plan: Plan, outward: bool) -> list[int]:
    """Numbers of the ``corridor-parity`` schemes (0: no sign in that slot).

    As in the authors' Normal and Inverse maps (``par_impar_par_impar``, "even odd even odd"
    from the start's corridor on), the signs line the corridors parallel to the plan's first one
    (the building's long corridors); cross corridors carry none. Taken in order of distance from
    the start, the k-th long corridor carries even numbers when k is even and odd numbers when k
    is odd, in the hundred-block 100 (k // 2). Its slots are split at the point of the corridor
    nearest the middle of the building: the half toward the corridor's end ``b`` is numbered
    first, then the other half, each rising away from the middle (``outward``) or toward it, the
    two walls alternating (1, 3, 5 ... from the middle to one end, then on from the middle to the
    other end)."""
    nums = [0] * len(slots)
    mid, start = np.array(plan.size) / 2, np.array(plan.start)
    first = np.subtract(plan.corridors[0].b, plan.corridors[0].a)
    long = []
    for j, cor in enumerate(plan.corridors):
        a, b = np.array(cor.a), np.array(cor.b)
        L = float(np.linalg.norm(b - a))
        if abs(first[0] * (b - a)[1] - first[1] * (b - a)[0]) > 1e-6 * L * np.linalg.norm(first):
            continue  # a cross corridor
        near = a + (b - a) * float(np.clip(np.dot(start - a, b - a) / L**2, 0.0, 1.0))
        long.append((float(np.linalg.norm(start - near)), j))
    for k, (_, j) in enumerate(sorted(long)):
        a, b = np.array(plan.corridors[j].a), np.array(plan.corridors[j].b)
        L = float(np.linalg.norm(b - a))
        t_mid = float(np.clip(np.dot(mid - a, (b - a) / L), 0.0, L))
        mine = [i for i, sl in enumerate(slots) if sl.corridor == j]
        halves = ([i for i in mine if slots[i].t >= t_mid], [i for i in mine if slots[i].t < t_mid])
        nxt = 100 * (k // 2) + (2 if k % 2 == 0 else 1)
        far = -1 if outward else 1
        for half in halves:
            for i in sorted(half, key=lambda i: (far * -abs(slots[i].t - t_mid), -slots[i].side)):
                nums[i] = nxt
                nxt += 2
    return nums


def generate_building(layout_name: str, scheme: str, seed: int, out: Path, res: float = 0.1,
                      spacing: float = 2.5, signs: int | None = None, goals: list | None = None,
                      name: str | None = None, density_delta: float = 2.5, planners: list | None = None,
                      floor: int = 2, scale: float = 1.0, skip: float = 0.0, letters: float = 0.0,
                      extension: bool = False, style: str = "plain", letter_case: str = "lower") -> Path:
    """Write ``out/map.png``, ``out/doors.csv`` and ``out/scenario.yaml``; returns the YAML path.

    ``signs`` trims the doors (not the numbers) at random to that count, keeping ``goals``;
    ``scale`` stretches the layout (see :func:`scaled`), corridors keeping their width. What real
    floors add (:func:`real_labels`): ``letters`` (0-0.9) the share of doors that share a room's
    number with a letter suffix, ``extension`` the last corridor renumbered in a hundred-block of
    its own, ``style`` how labels are written (:data:`STYLES`); then ``skip`` (0-0.95), the share
    of each prefix's number range left without a door (:func:`skip_numbers`: the statistic
    benchmarks/kth_labels.py measures on real floors). Goals given by number must survive these
    (the default goals are drawn after them).
    """
    if style not in STYLES:
        raise ScenarioError("<command line>", "--style", f"unknown label style {style!r}; valid: {', '.join(STYLES)}")
    if letter_case not in ("lower", "upper"):
        raise ScenarioError("<command line>", "--letter-case", f"unknown letter case {letter_case!r}; valid: lower, upper")
    if not (0.0 <= skip <= 0.95 and 0.0 <= letters <= 0.9):
        raise ScenarioError("<command line>", "--skip" if not 0.0 <= skip <= 0.95 else "--letters",
                            "a share: --skip between 0 and 0.95, --letters between 0 and 0.9")
    rng = np.random.default_rng(seed)
    plan = scaled(layout(layout_name, rng), scale)
    img, frame = rasterise(plan, res)
    slots = door_slots(plan, img, frame, spacing)
    nums = number_slots(slots, plan, scheme, img, frame, rng, floor)
    keep = [i for i, s in enumerate(slots) if s.ok and nums[i] > 0]  # 0: a slot the scheme leaves unsigned
    goal_set = {int(g) if isinstance(g, int) else g for g in goals or []}
    labels = {i: nums[i] for i in keep}
    if letters > 0.0 or extension or style != "plain":  # each from its own generator: a floor without them is the one before
        labels = real_labels(slots, keep, nums, np.random.default_rng([seed, 2]), letters, extension, style, floor,
                             letter_case)
    if skip > 0.0:
        labels = skip_numbers(labels, skip, goal_set, np.random.default_rng([seed, 1]))
    keep = [i for i in keep if i in labels]
    missing = goal_set - set(labels.values())
    if missing:
        raise ScenarioError("<command line>", "--goals", f"no door of this building carries {sorted(missing, key=str)} "
                            f"(numbers run {min(n for n in nums if n > 0)}..{max(nums)} with gaps at junctions)")
    if signs is not None:
        if signs > len(keep):
            raise ScenarioError("<command line>", "--signs", f"the building has room for {len(keep)} signs at {spacing} m spacing, fewer than {signs}")
        spare = [i for i in keep if labels[i] not in goal_set]
        drop = set(rng.choice(spare, size=len(keep) - signs, replace=False).tolist()) if len(keep) > signs else set()
        keep = [i for i in keep if i not in drop]
    free = img == 255
    snapped = [(labels[i], slots[i].x, slots[i].y, slots[i].facing) for i in keep]
    if not goals:
        goals = spread_goals(free, frame, snapped, plan.start)
    scen = scenario_dict(name or f"{layout_name}-{scheme}-{seed}", res, plan.start, goals, planners, density_delta)
    extra = "".join(f" --{k} {v}" for k, v in (("skip", skip), ("letters", letters), ("style", style)) if v not in (0.0, "plain"))
    extra += " --letter-case upper" if letters > 0.0 and letter_case == "upper" else ""
    extra += " --extension" if extension else ""
    return write_building(out, img, sorted(snapped, key=lambda s: (str(type(s[0])), s[0], s[1], s[2])), scen,
                          f"generated by `semsearch generate building --layout {layout_name} --numbering {scheme} --seed {seed}{extra}`")


def skip_numbers(labels: dict, share: float, goals: set, rng: np.random.Generator) -> dict:
    """``labels`` ({slot: label}) with doors taken away until, within each prefix, ``share`` of
    the numbers from its smallest to its largest carries no door (``1 - distinct / (max - min +
    1)``, as benchmarks/kth_labels.py measures real floors; rounded to whole numbers). The numbers
    taken are drawn at random among those that are neither a prefix's smallest or largest nor a
    goal's; every door of a number goes with it (a room's lettered doors together). A prefix
    already missing that share of its range keeps every door."""
    groups: dict = {}
    for i, lab in labels.items():
        p = parse_label(lab)
        if p is not None:
            groups.setdefault(p.prefix, {}).setdefault(p.number, []).append(i)
    protected = {(p.prefix, p.number) for p in map(parse_label, goals) if p is not None}
    drop = set()
    for prefix, by_number in groups.items():
        numbers = sorted(by_number)
        if len(numbers) < 3:
            continue
        span = numbers[-1] - numbers[0] + 1
        want = max(3, int(np.ceil((1.0 - share) * span)))  # numbers that keep a door
        spare = [n for n in numbers[1:-1] if (prefix, n) not in protected]
        k = min(len(spare), len(numbers) - want)
        if k > 0:
            for n in rng.choice(spare, size=k, replace=False):
                drop.update(by_number[int(n)])
    return {i: lab for i, lab in labels.items() if i not in drop}


def real_labels(slots: list[Slot], keep: list[int], nums: list[int], rng: np.random.Generator, letters: float,
                extension: bool, style: str, floor: int, letter_case: str = "lower") -> dict:
    """The label of each kept slot (``{slot: label}``), as real floors write them:

    - ``letters``: walking each wall's doors in order, a door starts a room of 2 doors (3 in one
      case of 4, 2.25 on average) with probability ``q = letters / (2.25 - 1.25 letters)``, so that
      the share of doors lettered is ``letters`` along a long wall (a room of ``g`` doors takes
      ``g`` of them, a door alone one: ``2.25 q / (2.25 q + 1 - q)``); the room's doors carry its
      first door's number with the suffixes a, b, c (``letter_case``), the others' numbers are
      skipped;
    - ``extension``: the last corridor with doors is renumbered by a whole number of hundreds,
      into a hundred-block above every other number (parity kept);
    - ``style``: ``plain`` numbers; ``wing``: a wing letter per corridor before the number
      (``K201``); ``dot``: floor-dot-room (``2.14``) when every number lies in the floor's
      hundred-block (else plain: a number outside it has no room part)."""
    num = {i: nums[i] for i in keep}
    if extension:
        cors = sorted({slots[i].corridor for i in keep})
        if len(cors) >= 2:
            last = [i for i in keep if slots[i].corridor == cors[-1]]
            rest = [num[i] for i in keep if slots[i].corridor != cors[-1]]
            offset = (max(rest) // 100 + 2) * 100 - (min(num[i] for i in last) // 100) * 100
            for i in last:
                num[i] += offset
    suffix = {i: "" for i in keep}
    if letters > 0.0:
        abc = "abc" if letter_case == "lower" else "ABC"
        walls: dict = {}
        for i in keep:
            walls.setdefault((slots[i].corridor, slots[i].side), []).append(i)
        for doors in walls.values():
            doors.sort(key=lambda i: slots[i].t)
            k = 0
            while k < len(doors):
                if rng.random() < letters / (2.25 - 1.25 * letters) and k + 1 < len(doors):
                    size = 3 if rng.random() < 0.25 and k + 2 < len(doors) else 2
                    room = doors[k : k + size]
                    for j, i in enumerate(room):
                        suffix[i] = abc[j]
                        num[i] = num[room[0]]
                    k += size
                else:
                    k += 1
    if style == "dot" and not all(floor * 100 <= num[i] < floor * 100 + 100 for i in keep):
        style = "plain"
    start = int(rng.integers(len(WING_LETTERS)))
    out = {}
    for i in keep:
        n, sfx = num[i], suffix[i]
        if style == "wing":
            out[i] = f"{WING_LETTERS[(start + slots[i].corridor) % len(WING_LETTERS)]}{n}{sfx}"
        elif style == "dot":
            out[i] = f"{floor}.{n - floor * 100:02d}{sfx}"
        else:
            out[i] = f"{n}{sfx}" if sfx else n
    return out


def generate_batch(out: Path, seeds: int = 3, layouts=LAYOUTS, schemes=SCHEMES, spacing: float = 3.0,
                   planners: list | None = None, runs: int = 3) -> list[Path]:
    """Every layout x numbering scheme x ``seeds`` seeds into ``out/<layout>-<scheme>-<seed>/``;
    each scenario runs ``planners`` (default greedy and nsos at alpha 0.9) ``runs`` times per goal.
    Returns the scenario paths (also listed, one per line, in ``out/index.txt``)."""
    planners = planners or [{"name": "greedy"}, {"name": "nsos", "alpha": 0.9}]
    paths = []
    for lay in layouts:
        for scheme in schemes:
            for seed in range(seeds):
                p = generate_building(lay, scheme, seed, out / f"{lay}-{scheme}-{seed}", spacing=spacing, planners=planners)
                scen = yaml.safe_load(p.read_text())
                scen["experiment"]["seeds"] = runs
                p.write_text(p.read_text().split("\n", 1)[0] + "\n" + yaml.safe_dump(scen, sort_keys=False))
                paths.append(p)
    (out / "index.txt").write_text("".join(f"{p.relative_to(out)}\n" for p in paths))
    return paths
