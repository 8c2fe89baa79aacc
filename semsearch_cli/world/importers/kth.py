"""Import a floor of the KTH campus floor-plan dataset (Aydemir, Jensfelt, Folkesson 2012).

Format: ``<Scale PixelDistance RealDistance>`` gives pixels per metre; each ``<space name=
"BUILDING_ROOM" type="KONTOR|KORRIDOR|...">`` has a ``<contour>`` of ``<linesegment x1 y1 x2 y2
type="Wall|Window|Portal" target="other space">``; pixel y points down.

The robot's free space is the union of the circulation spaces (rooms stay closed, as in the
authors' maps): those typed KORRIDOR, PASSAGE, HALL, KULVERT or ENTRE (``corridor_types``), and
untyped spaces joined by portals to several (three or more) other spaces: on the sample floor
these are two halls joined to stairs, lifts, toilets and a corridor, and a toilets' anteroom,
while an untyped space joined to one corridor is a room. Their boundary becomes a one-cell wall
and everything else "outside". Each Portal from a
room to a corridor is that room's door: a sign on the corridor wall at the portal's middle, facing
into the corridor, numbered by the room number after the underscore (a name that is not a number
is kept as text). A room with several doors gets its number on the first and ``NUMBER/2``, ... (text,
ignored by the number-based factors) on the others, since sign numbers must be unique. Default
goals are chosen only among signs the written scenario can read from the start's free space.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import cv2
import numpy as np

from ...errors import ScenarioError
from ...files import user_file
from ...geometry import GridFrame
from ..scenario_folder import map_image, scenario_dict, write_building
from ..labels import parse_label
from ...config import parse_scenario
from ...config.base import sign_label
from .mobilesim import MARGIN_M, snap_report, snap_signs, spread_goals
from ..ground_truth import build_world


def _label(name: str):
    """A space's sign label: its name after the floor prefix (``A4_2512`` -> 2512), in the one
    canonical form (config.base.sign_label); None when that is no label (empty, too long)."""
    tail = name.split("_", 1)[1] if "_" in name else name
    try:
        return sign_label(tail)
    except ValueError:
        return None


CORRIDOR_TYPES = ("KORRIDOR", "PASSAGE", "HALL", "KULVERT", "ENTRE")
MAX_SPACES = 5000  # spaces of one floor (the public set's largest floors have a few hundred)
MAX_SEGMENTS = 200_000  # line segments of one floor
MAX_COORD_M = 1e5  # m: a floor spans less than 100 km
MAX_CELLS = 50_000_000  # cells of the imported map


def _number(path: Path, where: str, el, attr: str, positive: bool = False) -> float:
    """Attribute ``attr`` of element ``el`` as a finite number (positive when asked); errors name
    the element and the attribute."""
    v = el.get(attr)
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise ScenarioError(str(path), f"{where} {attr}", f"expected a number, got {v!r}" if v is not None
                            else "missing") from None
    if not np.isfinite(x) or (positive and x <= 0):
        raise ScenarioError(str(path), f"{where} {attr}", f"expected a {'positive ' if positive else ''}finite number, "
                            f"got {v!r}")
    return x


def circulation(spaces, types=CORRIDOR_TYPES) -> set[str]:
    """Names of the spaces the robot drives in: typed as one of ``types``, or untyped and joined
    by portals to three or more other spaces."""
    types = {t.upper() for t in types}
    out = set()
    for s in spaces:
        kind = (s.get("type") or "").strip().upper()
        if kind in types:
            out.add(s.get("name"))
        elif not kind:
            joined = {ls.get("target") for ls in s.iter("linesegment") if ls.get("type") == "Portal" and ls.get("target")}
            if len(joined) >= 3:
                out.add(s.get("name"))
    return out


def import_kth(xml_path: Path, out: Path, res: float = 0.1, goals: list | None = None, name: str | None = None,
               density_delta: float = 2.5, corridor_types=CORRIDOR_TYPES, duplicates: str = "error") -> tuple[Path, list[str]]:
    """Write ``out/map.png``, ``out/doors.csv`` and ``out/scenario.yaml``; returns the YAML path
    and what happened to the signs (also in the YAML's header)."""
    user_file(xml_path, "KTH floor-plan file")
    try:
        root = ET.parse(xml_path).getroot()
    except ET.ParseError as exc:
        raise ScenarioError(str(xml_path), "", f"not valid XML: {exc}") from None
    scale = root.find("Scale")
    if scale is None:
        raise ScenarioError(str(xml_path), "Scale", "missing <Scale PixelDistance RealDistance> element")
    ppm = _number(xml_path, "Scale", scale, "PixelDistance", positive=True) / \
        _number(xml_path, "Scale", scale, "RealDistance", positive=True)
    spaces = root.findall("space")
    if len(spaces) > MAX_SPACES:
        raise ScenarioError(str(xml_path), "space", f"{len(spaces):,} spaces, more than the {MAX_SPACES:,} a floor may have")
    n_segs = sum(1 for _ in root.iter("linesegment"))
    if n_segs > MAX_SEGMENTS:
        raise ScenarioError(str(xml_path), "linesegment", f"{n_segs:,} line segments, more than the {MAX_SEGMENTS:,} a floor "
                            "may have")
    for k, s in enumerate(spaces):
        if not (s.get("name") or "").strip():
            raise ScenarioError(str(xml_path), f"space[{k}]", "a space without a name")
    corridors = circulation(spaces, corridor_types)
    if not corridors:
        found = sorted({(s.get("type") or "untyped") for s in spaces})
        raise ScenarioError(str(xml_path), "space", f"no circulation space (types {', '.join(corridor_types)}, or untyped "
                            f"spaces joined to several others): nothing for the robot to drive in. The floor's space "
                            f"types are {', '.join(found)}; name the circulation ones with --corridor-types")

    def seg(ls):
        where = f"space {ls_space[ls]!r}, linesegment"
        out = [_number(xml_path, where, ls, k) / ppm for k in ("x1", "y1", "x2", "y2")]
        if max(abs(v) for v in out) > MAX_COORD_M:
            raise ScenarioError(str(xml_path), f"{where} {[ls.get(k) for k in ('x1', 'y1', 'x2', 'y2')]}",
                                f"a coordinate {max(abs(v) for v in out):.3g} m from the origin: a floor spans at most "
                                f"{MAX_COORD_M:g} m (check Scale and the coordinates)")
        return out

    ls_space = {ls: s.get("name") for s in spaces for ls in s.iter("linesegment")}

    polys, portals, links = [], [], {}
    for s in spaces:
        segs = [seg(ls) for ls in s.iter("linesegment")]
        if s.get("name") in corridors:
            polys.append(np.array([[a, -b] for a, b, _, _ in segs]))
            for ls in s.iter("linesegment"):
                if ls.get("type") == "Portal" and ls.get("target") in corridors:
                    x1, y1, x2, y2 = seg(ls)
                    links.setdefault((s.get("name"), ls.get("target")), []).append(np.array([[x1, -y1], [x2, -y2]]))
        else:
            for ls in s.iter("linesegment"):
                if ls.get("type") == "Portal" and ls.get("target") in corridors and _label(s.get("name")) is not None:
                    x1, y1, x2, y2 = seg(ls)
                    portals.append((_label(s.get("name")), (x1 + x2) / 2, -(y1 + y2) / 2))
    polys = [p for p in polys if len(p) >= 3]
    if not polys:
        raise ScenarioError(str(xml_path), "space", "the circulation spaces have no contour (three or more line segments "
                            "each) to drive in")
    allpts = np.concatenate(polys)
    x0, y0 = allpts.min(axis=0) - MARGIN_M
    x1, y1 = allpts.max(axis=0) + MARGIN_M
    W, H = int(np.ceil((x1 - x0) / res)), int(np.ceil((y1 - y0) / res))
    if W * H > MAX_CELLS:
        raise ScenarioError(str(xml_path), "space", f"the circulation spans {x1 - x0:.0f} x {y1 - y0:.0f} m: {W * H:,} cells "
                            f"at {res:g} m, more than {MAX_CELLS:,}; give a coarser --resolution")
    frame = GridFrame(res, float(x0), float(y0), H, W)
    free = np.zeros((H, W), np.uint8)
    for p in polys:
        r, c = frame.to_cell(p[:, 0], p[:, 1])
        cv2.fillPoly(free, [np.stack([c, r], axis=1).round().astype(np.int32)], 1)
    # the two sides of a portal between corridors lie a wall's thickness apart: bridge them
    for (a, b), segs_ab in links.items():
        for pa in segs_ab:
            others = links.get((b, a), [])
            if not others:
                continue
            pb = min(others, key=lambda q: float(np.linalg.norm(q.mean(axis=0) - pa.mean(axis=0))))
            quad = cv2.convexHull(np.concatenate([pa, pb]).astype(np.float32))[:, 0, :]
            r, c = frame.to_cell(quad[:, 0], quad[:, 1])
            cv2.fillPoly(free, [np.stack([c, r], axis=1).round().astype(np.int32)], 1)
    # erode the outline by one cell: the wall is drawn inside each corridor's contour
    free = cv2.erode(free, np.ones((3, 3), np.uint8)).astype(bool)
    n, lab = cv2.connectedComponents(free.astype(np.uint8), connectivity=4)
    sizes = np.bincount(lab.ravel())
    sizes[0] = 0
    main = lab == int(np.argmax(sizes))
    d = cv2.distanceTransform(main.astype(np.uint8), cv2.DIST_L2, 5)
    r, c = np.unravel_index(int(np.argmax(d)), d.shape)
    sx, sy = frame.to_world(r, c)
    start = (round(float(sx), 2), round(float(sy), 2))

    seen: dict = {}
    raw = []
    for label, x, y in portals:
        k = seen.get(str(label), 0) + 1
        seen[str(label)] = k
        raw.append((label if k == 1 else f"{label}/{k}", x, y, None))  # no facing in the file: snapping gives it
    snapped, report = snap_report(raw, snap_signs(free, frame, raw), frame)
    links_rooms = sum(1 for sp in spaces if sp.get("name") not in corridors for ls in sp.iter("linesegment")
                      if ls.get("type") == "Portal" and ls.get("target") not in corridors)
    report.append(f"{len(raw)} room-to-circulation portals became signs; {links_rooms} portals between rooms "
                  f"(not reachable from the circulation) did not")

    header = f"imported from {xml_path.name} by `semsearch import kth`\n# " + "\n# ".join(report)
    chosen = goals or spread_goals(main, frame, snapped, start)
    scen = scenario_dict(name or xml_path.stem, res, start, chosen, None, density_delta, (frame.origin_x, frame.origin_y),
                         duplicates)
    path = write_building(out, map_image(free), snapped, scen, header)
    if goals:
        return path, report
    # default goals: only signs the written scenario can read from the start's free space
    world = build_world(parse_scenario(scen, path), out, str(path))
    # a sign is readable when a reachable pose reads it (what makes its shortest path finite, without
    # computing one path per sign: a floor of 2,000 rooms took 53 s that way)
    index = {str(n): i for i, n in enumerate(world.signs.number)}
    readable = [lab for lab, *_ in snapped if parse_label(lab) is not None and str(lab) in index
                and world.readable_mask(index[str(lab)]).any()]
    if not readable:
        raise ScenarioError(str(xml_path), "space", "no sign with a number (148, K202, 24D, ...) can be read from the "
                            "corridors' free space")
    ok = [g for g in chosen if g in readable]
    if len(ok) < len(chosen):
        keep = [s for s in snapped if s[0] in readable]
        ok = spread_goals(main, frame, keep, start)
        scen["goals"] = ok
        path = write_building(out, map_image(free), snapped, scen, header)
    return path, report
