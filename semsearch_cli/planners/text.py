"""The text of a decision, one per kind: the Gymnasium environments' text observations
(``semsearch_cli.envs``) and the ``llm`` planner's prompts (:mod:`semsearch_cli.planners.llm`)
are made by the same functions here (:func:`door_fields`, :func:`object_fields`,
:func:`indirect_fields`), so an agent in an environment reads what the planner's model reads;
they state the frame, the angles and the answer line alike."""

from __future__ import annotations

import math

import numpy as np

ANGLES_TEXT = ("Every angle is in degrees counter-clockwise from east in this fixed map frame (0 east, 90 north, "
               "180 west, -90 south), not relative to your heading; a bearing is the direction from you to a thing.")
FRAME_TEXT = "Frame: x points east and y north, in metres; distances are straight lines. " + ANGLES_TEXT


def deg(a: float) -> str:
    """An angle (rad) as whole degrees in (-180, 180], for the text observation."""
    d = round(math.degrees(a))
    return str(-((180 - d) % 360 - 180))


def spell(numbers) -> str:
    """Sorted action numbers in words: ``0, 1 or 64``; runs of three or more as ``4-9``."""
    runs: list[list[int]] = []
    for n in (int(v) for v in numbers):
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    items = []
    for a, b in runs:
        items += [str(a)] if a == b else [str(a), str(b)] if b == a + 1 else [f"{a}-{b}"]
    if not items:
        return "none"
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " or " + items[-1]


def answer_line(mask: np.ndarray) -> str:
    """The text observation's last line: the actions ``mask`` allows, and only those."""
    return f"Answer with one number: {spell(np.flatnonzero(mask))}."


# ---- door search ------------------------------------------------------------------------------
def door_targets(ctx, dist: np.ndarray, order: np.ndarray, cands) -> list[tuple[float, float, float, float]]:
    """The targets :func:`door_fields` shows: per candidate of ``order`` (indices into
    ``cands``), its path length (m, ``dist`` by candidate), its world x, y (m) and its branch
    direction theta_f (rad)."""
    xs, ys = ctx.belief.frame.to_world(cands.rows[order], cands.cols[order])
    return [(float(dist[i]), float(x), float(y), float(cands.theta[i])) for i, x, y in zip(order, xs, ys)]


def door_fields(goal, pose: tuple, travelled: float, belief, targets: list, mode: str = "actor",
                moves: str | None = None) -> dict:
    """A door-search decision as text, field by field: the llm planner's prompt and
    ``semsearch/DoorSearch-v1``'s text observation, one text. ``goal`` (the label), ``frame``,
    ``pose`` (``pose``: x, y m, heading rad; ``travelled`` m, left out when not finite),
    ``signs`` (the belief's signs read, where the robot stood to read each, nearest first),
    ``targets`` (:func:`door_targets`, numbered in their order; in the ``actor`` mode the last
    number looks at a wall; ``moves``, the primitive moves, in their place when given) and
    ``answer``; ``label`` the goal's label, and ``observation``, the fields in that order."""
    x, y, heading = pose
    b = belief
    label = str(goal)
    travelled_text = "" if not math.isfinite(travelled) else f"; travelled {travelled:.1f} m"
    f = {"goal": f"Goal: read the door sign {label}.", "label": label,
         "frame": ("Frame: x points east and y north, in metres; a target's distance is the length of the robot's path "
                   "to it, every other distance a straight line. " + ANGLES_TEXT),
         "pose": f"You are at x {x:.1f} m, y {y:.1f} m, heading {deg(heading)} deg{travelled_text}."}
    reads = b.reads.lists(np.arange(b.reads.n), b.spec.min_reads)
    signs = sorted(((str(lab), sx - x, sy - y) for lab, (_, sx, sy) in reads.items()), key=lambda s: s[1] ** 2 + s[2] ** 2)
    f["signs"] = ("Signs read so far, nearest first (where you stood when you read each): " + "; ".join(
        f"{lab} read {math.hypot(dx, dy):.1f} m away, bearing {deg(math.atan2(dy, dx))} deg" for lab, dx, dy in signs) + "."
        if signs else "No sign read yet.")
    n = len(targets)
    if moves is not None:
        f["targets"], f["answer"] = moves, answer_line(np.ones(10, bool))
    else:
        lines = [("Targets: frontier points on the edge of the explored area, nearest first along the path, each with the "
                  "direction in which unexplored space goes on beyond it" + (", or look at a wall:" if mode == "actor" else ":"))]
        lines += [f"[{k}] {dm:.1f} m along the path, bearing {deg(math.atan2(ty - y, tx - x))} deg, unexplored space "
                  f"towards {deg(theta)} deg" for k, (dm, tx, ty, theta) in enumerate(targets)]
        if mode == "actor":
            lines.append(f"[{n}] look at the nearest wall face no camera has read yet")
        f["targets"] = "\n".join(lines)
        f["answer"] = (answer_line(np.ones(n + 1, bool)) if mode == "actor" else
                       f"Answer with one JSON object mapping target numbers ({spell(range(n))}) to probabilities from 0 to 1.")
    f["observation"] = "\n".join(f[k] for k in ("goal", "frame", "pose", "signs", "targets", "answer"))
    return f


# ---- object search ------------------------------------------------------------------------------
def place_history(log, cls: str, hour: float, names: list) -> np.ndarray:
    """(P, 2) per place of ``names``: the recorded log's detections of ``cls`` there, in all and
    within an hour of ``hour`` (on the 24-hour clock)."""
    dets = log[log["class"] == cls]
    near = dets[np.abs(((dets["hour"] - hour + 12.0) % 24.0) - 12.0) <= 1.0]
    return np.array([[float((dets["place"] == n).sum()), float((near["place"] == n).sum())] for n in names],
                    np.float32).reshape(len(names), 2)


def object_fields(cls: str, hour: float, pose: tuple, travelled: float, names: list, places: dict, viewed,
                  history: np.ndarray, here: int | None, mask: np.ndarray, moves: str | None = None) -> dict:
    """An object-search decision as text, field by field (the object environment's text
    observation, and the llm planner's): ``goal``, ``frame``, ``pose``, ``places`` (the places,
    numbered when they are the choices, ``moves`` None) and ``answer`` (the numbers ``mask``
    allows), and ``observation``, all of them in that order. ``pose``: (x, y m, heading rad);
    ``viewed``: the places the camera has had in view; ``history``: :func:`place_history`;
    ``here``: the place just looked around at (left out of the choices), or None."""
    x, y, heading = pose
    macro = moves is None
    h = f"{hour:g}"
    lines = [("Choices: drive to a place and look around there. " if macro else "")
             + f"Places (distance, bearing; whether your camera has had the place in view in this "
             f"search; the detections of a {cls} there in the recorded log, in all and within an hour of hour {h}):"]
    for k, n in enumerate(names):
        px, py = places[n]
        dx, dy = px - x, py - y
        lines.append(f"{f'[{k}] ' if macro else ''}{n}: {math.hypot(dx, dy):.1f} m, bearing {deg(math.atan2(dy, dx))} deg, "
                     f"{'viewed' if n in viewed else 'not viewed yet'}; log: {history[k, 0]:.0f} detections, "
                     f"{history[k, 1]:.0f} within the hour")
    if not macro:
        lines.append(moves)
    elif here is not None:
        lines.append(f"[{here}] {names[here]} is left out: you have just looked around there.")
    f = {"goal": f"Goal: find a {cls}; the request was made at hour {h} of the day.", "frame": FRAME_TEXT,
         "pose": f"You are at x {x:.1f} m, y {y:.1f} m, heading {deg(heading)} deg; travelled {travelled:.1f} m.",
         "places": "\n".join(lines), "answer": answer_line(mask)}
    f["observation"] = "\n".join(f[k] for k in ("goal", "frame", "pose", "places", "answer"))
    return f


# ---- indirect search ----------------------------------------------------------------------------
def indirect_fields(target: str, room: str, scale: float, t_s: float, time_limit: float, pose: tuple, seen: dict,
                    p: np.ndarray, frame, choices: str, mask: np.ndarray) -> dict:
    """An indirect-search decision as text, field by field (the indirect environment's text
    observation, and the llm planner's): ``goal``, ``frame``, ``pose``, ``objects`` (the
    secondary objects detected, ``seen``: class -> (x, y) m, by name), ``likeliest`` (the five
    likeliest cells of ``p``, the normalised map of the target on ``frame``), ``choices`` (given)
    and ``answer`` (the numbers ``mask`` allows), and ``observation``, all of them in that order."""
    x, y, heading = pose
    top = np.argsort(-p.ravel(), kind="stable")[:5]  # ties: row-major from the north-west corner
    xs, ys = frame.to_world(*np.unravel_index(top, p.shape))
    objects = [f"{c} at x {ox:.2f} m, y {oy:.2f} m ({math.hypot(ox - x, oy - y):.2f} m away, bearing "
               f"{deg(math.atan2(oy - y, ox - x))} deg)" for c, (ox, oy) in sorted(seen.items())]
    f = {"goal": f"Goal: find the {target} in room {room}; your camera detects it up to {scale:g} m away. "
                 f"Time used: {t_s:.1f} s of {time_limit:g} s.",
         "frame": FRAME_TEXT + " Positions are measured from the room's south-west corner.",
         "pose": f"You are at x {x:.2f} m, y {y:.2f} m, heading {deg(heading)} deg.",
         "objects": "Other objects detected: " + ("; ".join(objects) or "none yet") + ".",
         "likeliest": f"Likeliest cells of the {target} (cell centre, probability): "
                      + "; ".join(f"({cx:.2f}, {cy:.2f}) m {p.ravel()[i]:.4f}" for cx, cy, i in zip(xs, ys, top)) + ".",
         "choices": choices, "answer": answer_line(mask)}
    f["observation"] = "\n".join(f[k] for k in ("goal", "frame", "pose", "objects", "likeliest", "choices", "answer"))
    return f


def lattice_choices(nx: int, ny: int, step: float, replan_every: float) -> str:
    """The indirect macro choices as text: ``8 k + h``, lattice point ``k`` and heading ``h``."""
    return (f"Choices: answer 8 k + h to drive to lattice point k and turn to heading h x 45 deg "
            f"(h 0-7: 0 east, 2 north, 4 west, 6 south); point k = i + {nx} j is at "
            f"x = {step / 2:g} + {step:g} i m, y = {step / 2:g} + {step:g} j m (i 0-{nx - 1}, j 0-{ny - 1}), and the "
            f"points you cannot stand on are left out. You choose again after {replan_every:g} s, "
            "on arrival, or when an object is detected.")
