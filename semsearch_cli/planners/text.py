"""The wording every text a language model reads shares: the Gymnasium environments' text
observations (``semsearch_cli.envs``) and the ``llm`` planner's prompts
(:mod:`semsearch_cli.planners.llm`) state the frame, the angles and the answer line alike."""

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
