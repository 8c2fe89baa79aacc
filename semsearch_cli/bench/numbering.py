"""The numbering ablation: a floor's labels permuted among its own signs (``--numbering``).

Every permutation is a bijection of the floor's distinct labels onto themselves, so each sign keeps
its place, the floor keeps its set of labels (and any sign that shared a label with another still
does), and a goal is the same door under its new label: the episodes (start, goal door, shortest
path) do not move, and a planner's rows under two numberings pair episode by episode.

- ``true``: the floor as built.
- ``shuffled``: a random bijection of all the floor's labels (seeded by the floor): the labels
  carry nothing a planner could use; the difference true minus shuffled is a planner's *semantic
  gain*.
- ``parity-flipped``: within each prefix (a wing, a floor), the floor's numbers in order are paired
  greedily, each with the next one when the two differ in parity (``23`` with ``24``; with ``26``
  when 24 and 25 are skipped), and each pair's labels trade their numbers (a suffix kept: ``23a``
  becomes ``24a`` where the floor has it). On a floor with one parity per wall, the walls trade
  parities and the order along the corridors stays; on a floor whose walls carry both parities
  (``loop``) it moves signs by one place along the wall.
- ``reversed``: within each prefix, the labels in order of number (then suffix) are reversed: the
  k-th smallest trades with the k-th largest, suffix and all: numbers fall where they rose.

Labels without a number (``Lab``) keep their place under ``parity-flipped`` and ``reversed``.
"""

from __future__ import annotations

import hashlib

import numpy as np

from ..world.labels import parse_label

NUMBERINGS = ("true", "shuffled", "parity-flipped", "reversed")


def relabel(labels: list, how: str, seed: str) -> dict:
    """The bijection ``{label: new label}`` of ``how`` (one of :data:`NUMBERINGS`) over the
    distinct ``labels`` of a floor; ``seed`` (text, e.g. the floor's id) seeds ``shuffled``."""
    distinct = list(dict.fromkeys(labels))
    if how == "true":
        return {a: a for a in distinct}
    if how == "shuffled":
        words = np.frombuffer(hashlib.sha256(f"shuffled/{seed}".encode()).digest()[:16], "<u4")
        order = np.random.default_rng([int(w) for w in words]).permutation(len(distinct))
        return {a: distinct[int(k)] for a, k in zip(distinct, order)}
    groups: dict[str, list] = {}  # prefix -> its numbered labels
    for a in distinct:
        p = parse_label(a)
        if p is not None:
            groups.setdefault(p.prefix, []).append((p.number, p.suffix, a))
    out = {a: a for a in distinct}
    if how == "reversed":
        for items in groups.values():
            order = sorted(items, key=lambda t: (t[0], t[1], str(t[2])))
            for a, b in zip(order, reversed(order)):
                out[a[2]] = b[2]
        return out
    if how == "parity-flipped":
        for items in groups.values():
            numbers = sorted({n for n, *_ in items})
            flip = {n: n for n in numbers}
            k = 0
            while k + 1 < len(numbers):
                a, b = numbers[k], numbers[k + 1]
                if (a - b) % 2:
                    flip[a], flip[b] = b, a
                    k += 2
                else:
                    k += 1
            _swap_numbers(items, flip, out)
        return out
    raise ValueError(f"unknown numbering {how!r}; valid: {', '.join(NUMBERINGS)}")


def _swap_numbers(items: list, flip: dict, out: dict) -> None:
    """``out[label]``: the label of number ``flip[n]`` with the same suffix, where the floor has
    one (else the label stays). As ``flip`` is an involution of the numbers, so is this of the
    labels: a bijection. (Two labels that read as the same number and suffix, ``K-201`` and
    ``K201``: one of them trades, the other keeps its place.)"""
    by = {(n, s): a for n, s, a in items}
    for n, s, a in items:
        b = by.get((flip[n], s))
        if b is not None and by[(n, s)] is a:
            out[a] = b
