"""The one decision point of every run, and who answers it.

A run stops for a decision in one place: a kind's re-plan (``Search.plan``, a generator) yields a
:class:`DecisionPoint` and is sent back the choice. Whoever drives the run answers it the same way:

- the batch (:class:`Seat`): the run's planner answers (``point.ask()``);
- a recording batch (:class:`Recording`, ``semsearch run --decisions``): the planner answers, and
  the choice is kept in a few bytes (``point.encode``), with the random generator's state after
  the planner's turn when the planner drew from it;
- a replay (:class:`Replay`, ``semsearch verify``): the recorded choices answer, decoded
  (``point.decode``), the generator put back where the planner left it; no planner runs;
- a Gymnasium environment (``semsearch_cli.envs``): the agent's action answers, through
  :class:`~semsearch_cli.tasks.loop.Session`.

A replay is exact when the run depends on its planner only through what the record keeps: the
choices; the run's one generator (sensing and planners draw from it), restored after each
decision at which the planner drew; what the planner leaves behind that the run goes on to read
(door search: the path search a planner ran over the belief, which the path to its target reuses
when it started from the robot's cell; the kind's ``DecisionPoint.keep`` and ``restore``); and
what a planner is besides its choices (door planners' ``replan_on_signs``, indirect planners'
masks: each kind's planner protocol names them, ``run_attributes``, and a replay seats a
:class:`StandIn` that has them). A planner that changes the run any other way (writing into the
belief it is shown) does not replay, and ``semsearch verify`` names its runs.

The record of a run (``decisions/<run>.json``)::

    {"format": "semsearch-decisions", "version": 1, "kind": "doors", "planner": "nsos[alpha=0.9]",
     "goal": "148", "episode": 0, "seed": 0, "fingerprint": "...", "engine": 1,
     "seats": {"nsos[alpha=0.9]": {"replan_on_signs": false}},
     "decisions": [[412, 1033], 0, [398, 1100], null], "rng": {"3": "<state>.<has_uint32>.<uinteger>"}}

``decisions`` holds one item per decision point in the order the run met them (a chain's stages,
kept and from scratch, in the order they ran): each kind's code of the choice (see its
``Codec``), ``0`` for "the same choice as the decision before", or ``"budget"`` where the
planner's own budget (a language model's ``max_calls``) ended the run; ``rng`` the generator's state
(PCG64, hexadecimal) after the decisions at which the planner drew from it; ``left`` what the
planner left behind that the run reads (door search: the path search it ran, which the path to
its target reuses), by decision.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..errors import BudgetSpent

FORMAT = "semsearch-decisions"
VERSION = 1
SAME = 0  # a decision's item: the same choice as the decision before
SPENT = "budget"  # a decision's item: the planner's own budget (a language model's calls) ended the run here


class ReplayError(Exception):
    """A replay that cannot go on: the run asked for a decision the record does not have, or a
    recorded choice that the run cannot take."""


@dataclass(frozen=True)
class Codec:
    """How a kind writes a choice in a few bytes (``encode``: a JSON list, or None) and reads it
    back (``decode``); ``decode(encode(c))`` is a choice the run takes exactly as it took ``c``."""

    encode: Callable[[Any], Any]
    decode: Callable[[Any], Any]


@dataclass
class DecisionPoint:
    """A run stopped for a decision.

    kind : the kind of search that asks (doors, objects, indirect); observation : what a planner
    of that kind reads (``DoorContext``, ``ObjectContext``, ``IndirectContext``); choices : what
    may be chosen (door search: the frontier ``Candidates``; object search: the places, name ->
    (x, y) m; indirect search: the (H, W) cells the robot may stand on); mask : bool, the choices
    legal now (one per candidate, per place, per cell); ask : the seated planner's answer;
    codec : the kind's :class:`Codec`; rng : the run's generator. A choice may also be None: no
    target (door search: look at the unread walls; object search: nothing left to look at).
    keep, restore : what a planner leaves behind that the run goes on to read besides its choice
    and the generator (door search: the path search it ran, which the path to its target reuses),
    as a JSON list (or None), and how a replay puts it back."""

    kind: str
    observation: Any
    choices: Any
    mask: np.ndarray
    ask: Callable[[], Any]
    codec: Codec
    rng: np.random.Generator
    keep: Callable[[], Any] | None = None  # what the planner left behind that the run reads (JSON list or None)
    restore: Callable[[Any], None] | None = None  # put it back in a replay

    def encode(self, choice) -> Any:
        return self.codec.encode(choice)

    def decode(self, item) -> Any:
        return self.codec.decode(item)


def ask(point: DecisionPoint):
    """The batch's answer to a decision point: the seated planner's."""
    return point.ask()


# ---- who sits in the planner's seat -------------------------------------------------------------
class Seat:
    """The batch's seat: each search's planner is the variant's, built afresh, and it answers.

    The seat keeps the planners it built for the run (``seated``), so that the run can read what
    they report of themselves: a cost (a language model's calls and tokens, :meth:`costs`), a
    transcript (:meth:`transcripts`), why a planner's own budget ended the run (:meth:`notes`).
    ``run``: the run's identity (scenario, kind, planner label, goal, episode, seed), which a planner
    that wants it (``start_run(identity)``, e.g. to find its transcript) is given when built,
    with ``stage`` its place among the run's planners (0, 1, ... in a chain)."""

    def __init__(self):
        self.seated: list = []
        self.run: dict = {}

    def planner(self, variant):
        return self.seat(variant.build())

    def seat(self, planner):
        """Keep ``planner`` among the run's, and give it the run's identity when it asks for it."""
        start = getattr(planner, "start_run", None)
        if callable(start) and self.run:
            start({**self.run, "stage": len(self.seated)})
        self.seated.append(planner)
        return planner

    decide = staticmethod(ask)

    def costs(self) -> dict:
        """The costs the run's planners report (``costs()``: column -> number), summed over them."""
        out: dict = {}
        for p in self.seated:
            report = getattr(p, "costs", None)
            if callable(report):
                for k, v in report().items():
                    out[k] = out.get(k, 0) + v
        return out

    def transcripts(self) -> list:
        """The transcripts of the run's planners that keep one (``transcript``: a list of JSON
        objects), in the order they were seated."""
        return [t for t in (getattr(p, "transcript", None) for p in self.seated) if t]

    def notes(self) -> str:
        """Why a planner's own budget ended the run (``spent``), if one did."""
        return "; ".join(s for s in (getattr(p, "spent", "") for p in self.seated) if s)

    def finish(self) -> None:
        """The run is over: each planner that checks something then (``finish_run()``: a replayed
        transcript used up) does."""
        for p in self.seated:
            end = getattr(p, "finish_run", None)
            if callable(end):
                end()


def run_attributes(planner) -> dict:
    """The attributes of ``planner`` that shape a run besides its choices (its protocol's
    ``run_attributes``), as JSON values."""
    out = {}
    for a in getattr(planner, "run_attributes", ()):
        v = getattr(planner, a)
        out[a] = v.item() if isinstance(v, np.generic) else v
    return out


class Recording(Seat):
    """The batch's seat, keeping each choice (see the module docstring): :meth:`record`."""

    def __init__(self):
        super().__init__()
        self.items: list = []
        self.rng: dict[str, str] = {}
        self.left: dict[str, list] = {}
        self.seats: dict[str, dict] = {}
        self._last = None

    def planner(self, variant):
        p = self.seat(variant.build())  # seated first: a planner may set its run attributes when the run starts
        self.seats.setdefault(variant.label, run_attributes(p))
        return p

    def decide(self, point: DecisionPoint):
        before = rng_word(point.rng)
        try:
            choice = point.ask()
        except BudgetSpent:  # the planner's own budget ended the run here: so does the replay
            self.items.append(SPENT)
            raise
        code = point.encode(choice)
        if code is not None and not isinstance(code, list):  # 0 stands for "the same again"
            raise TypeError(f"the {point.kind} codec wrote {code!r}: a choice's code is a JSON list, or None")
        left = point.keep() if point.keep is not None else None
        json.dumps([code, left], allow_nan=False)  # a code that no record could hold fails its run, not the batch
        after = rng_word(point.rng)
        k = len(self.items)
        self.items.append(SAME if k and code == self._last else code)
        self._last = code
        if after != before:
            self.rng[str(k)] = after
        if left is not None:
            self.left[str(k)] = left
        return choice

    def record(self, kind: str) -> dict:
        """The run's record (without its identity, which the runner adds)."""
        return {"format": FORMAT, "version": VERSION, "kind": kind, "seats": self.seats, "decisions": self.items,
                "rng": self.rng, "left": self.left}


@dataclass
class StandIn:
    """What sits in a planner's seat in a replay: its label and its run attributes, no code."""

    name: str
    attributes: dict = field(default_factory=dict)

    def __getattr__(self, key):
        try:
            return self.__dict__["attributes"][key]
        except KeyError:
            raise AttributeError(key) from None


class Agent(Seat):
    """The seat of choices made outside the run: a Gymnasium environment's agent, a front end's
    user, a robot's operator. What sits in the planner's seat is a :class:`StandIn` named
    ``name`` with ``attributes``, the run attributes the kind's search reads (door search:
    ``replan_on_signs``; indirect search: ``masks``, ``negative``, ``uses_map``,
    ``replan_on_detection``); every choice comes through
    :meth:`~semsearch_cli.tasks.base.OpenEpisode.answer`, so :meth:`decide` refuses."""

    def __init__(self, name: str = "agent", **attributes):
        super().__init__()
        self.name, self.attributes = name, attributes

    def planner(self, variant):
        return self.seat(StandIn(self.name, dict(self.attributes)))

    def decide(self, point: DecisionPoint):
        raise RuntimeError(f"the {self.name} answers each {point.kind} decision through OpenEpisode.answer(choice); "
                           "a kind whose episode() answers its own decisions (before semsearch 0.4.0) cannot be "
                           "stepped so: write its steps()")


class Replay(Seat):
    """A recorded run's choices answering its decision points (see the module docstring);
    :meth:`finish` checks that every one was asked for."""

    def __init__(self, record: dict):
        super().__init__()
        check_record(record)
        self.items = list(record["decisions"])
        self.rng = {int(k): v for k, v in record.get("rng", {}).items()}
        self.left = {int(k): v for k, v in record.get("left", {}).items()}
        self.seats = record.get("seats", {})
        self.k = 0
        self._last = None

    def planner(self, variant):
        if variant.label not in self.seats:
            raise ReplayError(f"the record seats no planner {variant.label!r} (it seats {', '.join(self.seats) or 'none'})")
        return StandIn(variant.label, dict(self.seats[variant.label]))

    def decide(self, point: DecisionPoint):
        if self.k >= len(self.items):
            raise ReplayError(f"the run asks for decision {self.k + 1}, and the record holds {len(self.items)}")
        item = self.items[self.k]
        if item == SPENT:
            self.k += 1
            raise BudgetSpent("the planner's own budget ended the run here (as the record says)")
        if item == SAME and not isinstance(item, bool) and self.k:
            item = self._last
        try:
            choice = point.decode(item)
        except (TypeError, ValueError, IndexError, KeyError) as exc:
            raise ReplayError(f"decision {self.k + 1}: {json.dumps(item)[:60]} is not a {point.kind} choice ({exc})") from None
        if self.k in self.left:
            if point.restore is None:
                raise ReplayError(f"decision {self.k + 1}: the record keeps what the planner left behind, and a {point.kind} "
                                  "decision has nothing to put back")
            try:
                point.restore(self.left[self.k])
            except (TypeError, ValueError, IndexError, KeyError) as exc:
                raise ReplayError(f"decision {self.k + 1}: {json.dumps(self.left[self.k])[:60]} does not put back what the "
                                  f"planner left ({exc})") from None
        if self.k in self.rng:
            set_rng(point.rng, self.rng[self.k])
        self._last = item
        self.k += 1
        return choice

    def finish(self) -> None:
        if self.k != len(self.items):
            raise ReplayError(f"the run asked for {self.k} decisions, and the record holds {len(self.items)}")


def check_record(record) -> None:
    """A :class:`ReplayError` unless ``record`` is a decisions record this version reads."""
    if not isinstance(record, dict) or record.get("format") != FORMAT:
        raise ReplayError(f"not a decisions record (no \"format\": \"{FORMAT}\")")
    if record.get("version") != VERSION:
        raise ReplayError(f"a decisions record of version {record.get('version')!r}; this semsearch reads version {VERSION}")
    maps = {k: record.get(k, {}) for k in ("rng", "left", "seats")}
    if not isinstance(record.get("decisions"), list) or not all(isinstance(m, dict) for m in maps.values()):
        raise ReplayError("a decisions record holds a list \"decisions\" and the objects \"rng\", \"left\" and \"seats\"")
    for name in ("rng", "left"):
        bad = next((k for k in maps[name] if not (isinstance(k, str) and k.isascii() and k.isdigit() and len(k) <= 9)), None)
        if bad is not None:
            raise ReplayError(f"\"{name}\" is keyed by decision numbers (0, 1, ...), not {str(bad)[:20]!r}")
    bad = next((k for k, v in maps["seats"].items() if not isinstance(v, dict)), None)
    if bad is not None:
        raise ReplayError(f"\"seats\" maps each planner to its attributes (an object), not {str(maps['seats'][bad])[:20]!r}")


# ---- the generator's state ------------------------------------------------------------------------
def rng_word(rng: np.random.Generator) -> str:
    """The state of a run's generator (PCG64) as one short word: the 128-bit state, then the
    buffered 32-bit half (a flag and its value), in hexadecimal."""
    s = rng.bit_generator.state
    return f"{s['state']['state']:x}.{s['has_uint32']}.{s['uinteger']:x}"


def set_rng(rng: np.random.Generator, word: str) -> None:
    """Put ``rng`` in the state :func:`rng_word` wrote (its increment, fixed for a run, kept)."""
    try:
        state, has, u = word.split(".")
        s = rng.bit_generator.state
        s["state"]["state"], s["has_uint32"], s["uinteger"] = int(state, 16), int(has), int(u, 16)
        rng.bit_generator.state = s
    except (AttributeError, ValueError, TypeError, KeyError, OverflowError) as exc:
        raise ReplayError(f"a generator state {str(word)[:40]!r} that does not read ({exc})") from None
