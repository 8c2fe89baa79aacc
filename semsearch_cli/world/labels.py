"""Room labels as real buildings write them: ``148``, ``K202``, ``24D``, ``2.14``, ``B-105``,
``3-107a``, ``A9A``, and our KTH import's ``2512/2`` (a room's second door).

A label is read as a prefix (a wing, a floor: ``K``, ``B``, ``2``), a number and a suffix (a room
beside the number's: ``D``, ``a``; or the door index ``/2``). The number is the first run of digits
after which only a short letter suffix (at most three letters) and a door index may follow; what
comes before it is the prefix, its trailing separators (``.``, ``-``, ``_``, a space) dropped. So
``2.14`` is floor 2, room 14, and ``3-107a`` is wing 3, room 107, suffix a. A label with no digits
(``Lab``, ``Kitchen``) has no number; digits are ASCII ``0-9`` (``30²`` has none), and a
label is at most 64 characters (:data:`~semsearch_cli.config.base.MAX_LABEL`).

How the planners use it (nsos, the draft planner): a goal is matched on the whole label, and the
semantic terms reason on the numbers of the signs that share the goal's prefix (a sign with a
suffix counts with its number: ``24D`` stands beside 24). Plain numbers have an empty prefix, so
a building numbered 101, 102, ... reads as before.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..config.base import MAX_LABEL, MAX_LABEL_DIGITS

# ASCII digits only (re.ASCII): a superscript or an Arabic-Indic digit is text, never part of a number
_LABEL = re.compile(r"(?P<prefix>.*?)(?P<number>[0-9]+)(?P<suffix>[A-Za-z]{0,3}(?:/[0-9]+)?)", re.ASCII)


@dataclass(frozen=True)
class SignLabel:
    """A label read as (prefix, number, suffix)."""

    prefix: str
    number: int
    suffix: str


@lru_cache(maxsize=65536)
def parse_label(label) -> SignLabel | None:
    """``label`` (an int or text) as a :class:`SignLabel`, or None when it carries no number."""
    if isinstance(label, bool):
        return None
    if isinstance(label, (int, np.integer)):
        return SignLabel("", int(label), "") if 0 <= label < 10 ** MAX_LABEL_DIGITS else None
    text = str(label).strip()
    if len(text) > MAX_LABEL:  # refused where labels are read (config.base.sign_label); never parsed here
        return None
    m = _LABEL.fullmatch(text)
    if m is None or len(m["number"]) > MAX_LABEL_DIGITS:
        return None
    return SignLabel(m["prefix"].rstrip(".-_ "), int(m["number"]), m["suffix"])
