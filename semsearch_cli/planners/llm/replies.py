"""Reading a model's reply: a choice, or the reason it is not one (which the model is told when it
is asked again, and the transcript keeps). Nothing here guesses: a reply that does not name one
legal choice is invalid, never mapped to a default.

- an actor's reply names one number: the whole reply is that number (``3``, ``[3]``, ``3.``,
  ``"3"``), or its last line that starts with ``Answer`` gives it (``Answer: 3``), so that a
  model that reasons first may; a reasoning model's ``<think>...</think>`` block is set aside;
- an estimator's reply is one JSON object (bare, or in a ```json fence) mapping shown targets'
  numbers to probabilities in [0, 1]; a target it leaves out counts as 0.
"""

from __future__ import annotations

import json
import math
import re

MAX_REPLY = 100_000  # characters of a reply that are read (a longer one is invalid: "too long")
THINK = re.compile(r"<think>.*?</think>", re.S | re.I)
BARE = re.compile(r"\s*[\[\"'(]?\s*(-?[0-9]+)\s*[\]\"')]?\s*\.?\s*")
ANSWER = re.compile(r"^\s*\**\s*answer\s*\**\s*[:=\-]?\s*\**\s*[\[\"'(]?\s*(-?[0-9]+)\s*[\]\"')]?\s*\.?\s*\**\s*$", re.I | re.M)
FENCE = re.compile(r"```(?:json)?\s*(.*?)```", re.S | re.I)


def _text(reply) -> tuple[str | None, str]:
    if reply is None or not isinstance(reply, str):
        return None, "the reply is empty"
    if len(reply) > MAX_REPLY:
        return None, f"the reply is too long ({len(reply):,} characters)"
    text = THINK.sub("", reply).strip()
    if not text:
        return None, "the reply is empty"
    return text, ""


def parse_number(reply, allowed: range) -> tuple[int | None, str]:
    """An actor's reply -> (the number it names, "") or (None, why not)."""
    text, why = _text(reply)
    if text is None:
        return None, why
    m = BARE.fullmatch(text)
    found = [m.group(1)] if m else ANSWER.findall(text)
    if not found:
        return None, "the reply is not one number (answer with the number alone)"
    n = int(found[-1])
    if n not in allowed:
        return None, f"{n} is not one of the choices offered"
    return n, ""


def parse_probabilities(reply, targets: int) -> tuple[dict[int, float] | None, str]:
    """An estimator's reply -> ({target: probability}, "") or (None, why not)."""
    text, why = _text(reply)
    if text is None:
        return None, why
    fenced = FENCE.search(text)
    body = fenced.group(1).strip() if fenced else text
    try:
        obj = json.loads(body)
    except ValueError:
        return None, "the reply is not one JSON object"
    if not isinstance(obj, dict):
        return None, "the reply is JSON, but not an object mapping targets to probabilities"
    out: dict[int, float] = {}
    for k, v in obj.items():
        key = k.strip().strip("[]") if isinstance(k, str) else k
        try:
            t = int(key)
        except (TypeError, ValueError):
            return None, f"{str(k)[:20]!r} is not a target's number"
        if str(t) != str(key) or not 0 <= t < targets:
            return None, f"{str(k)[:20]!r} is not one of the targets offered (0 to {targets - 1})"
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not 0 <= v <= 1:
            return None, f"the probability of target {t} is {str(v)[:20]}, not a number from 0 to 1"
        out[t] = float(v)
    if not out:
        return None, "the object gives no target a probability"
    return out, ""
