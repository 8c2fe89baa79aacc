"""One episode handle for every driver (``Task.open`` -> ``OpenEpisode``): stepped decision by
decision from outside, it is the batch's run, for every kind; an agent's seat answers from
outside only; primitive steps and the handle's misuse are refused with a sentence; a kind written
before 0.4.0 (``episode(..., decide)``) still runs, with a warning naming its replacement."""

import warnings
from pathlib import Path

import numpy as np
import pytest

from semsearch_cli.envs.base import compass_move, compass_step
from semsearch_cli.planners import Variant
from semsearch_cli.runner import Loaded
from semsearch_cli.tasks import TASKS, OpenEpisode, Outcome, register_task
from semsearch_cli.tasks.decisions import Agent, DecisionPoint, Recording, Replay
from semsearch_cli.tasks.doors import DoorSearch, DoorTask
from semsearch_cli.tasks.loop import run_loop

ROOT = Path(__file__).resolve().parents[1]
CASES = [("demo", Variant("nsos", (("alpha", 0.9),)), 0), ("office", Variant("lsos", ()), 1),
         ("indirect_quick", Variant("ISC-OP-SM", ()), 0)]


def task_of(config: str):
    return Loaded.load(ROOT / "configs" / f"{config}.yaml").task


def same(a, b) -> None:
    assert (a.outcome, a.distance_m, a.steps, a.decisions, a.left_m) == (b.outcome, b.distance_m, b.steps, b.decisions, b.left_m)
    assert np.array_equal(a.path, b.path)


@pytest.mark.parametrize("config,variant,k", CASES, ids=[c[0] for c in CASES])
def test_stepped_from_outside_it_is_the_batch_run(config, variant, k):
    task = task_of(config)
    ep = task.episodes[k]
    batch = task.run(variant, ep, 3)
    h = task.open(variant, ep, 3)
    assert isinstance(h, OpenEpisode) and h.point is None and h.outcome is None
    point, n = h.start(), 0
    while isinstance(point, DecisionPoint):
        assert h.point is point and h.observation is point.observation and h.mask is point.mask
        point = h.answer(point.ask())  # the planner's answer, carried by hand
        n += 1
    assert point == h.outcome == batch.outcome and h.point is None
    same(h.result(), batch)
    assert n >= batch.decisions > 0
    drop = lambda rows: [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]  # noqa: E731
    assert drop(h.rows()) == drop(task.rows(variant, ep, 3, batch)) and h.rows()[0]["planner"] == variant.label


def test_an_agent_answering_a_record_travels_what_the_batch_recorded():
    """The agent's seat gets its choices from outside: here the recorded choices of a batch run,
    decoded by each point's codec; the run is the recorded one."""
    task = task_of("demo")
    ep, v = task.episodes[1], Variant("greedy", ())
    rec = Recording()
    batch = task.run(v, ep, 0, seat=rec)
    record = rec.record(task.planner_kind)
    h = task.open(None, ep, 0, seat=Agent("agent", replan_on_signs=record["seats"]["greedy"]["replan_on_signs"]))
    assert h.variant.label == "agent"
    items, last = iter(record["decisions"]), None
    point = h.start()
    while isinstance(point, DecisionPoint):
        item = next(items)
        item = last if item == 0 else item
        last = item
        point = h.answer(point.decode(item))
    assert next(items, "none left") == "none left"
    same(h.result(), batch)
    replayed = task.run(v, ep, 0, seat=Replay(record))  # and the replay seat, through the same handle
    same(replayed, batch)


def test_an_agent_seat_answers_only_from_outside():
    task = task_of("demo")
    h = task.open(None, task.episodes[0], 0, seat=Agent())
    with pytest.raises(RuntimeError, match="answers each doors decision through OpenEpisode.answer"):
        h.play()


def test_primitive_steps_go_through_the_same_episode():
    task = task_of("demo")
    h = task.open(None, task.episodes[0], 0, seat=Agent(replan_on_signs=True))
    assert h.start(primitive=True) is None and h.search is not None
    x0 = h.state.x

    def east(st):
        st.x += 0.1
        return 0.1

    assert h.take(east) is None
    assert h.state.steps == 1 and h.state.x == pytest.approx(x0 + 0.1) and h.state.distance == pytest.approx(0.1)
    assert len(h.state.trail) == 2
    n = 1
    while (out := h.take(lambda st: 0.0)) is None:
        n += 1
    assert out == h.outcome == "budget" and h.state.steps == task.max_steps() == n + 1
    assert h.result().outcome == "budget"
    with pytest.raises(RuntimeError, match="has not ended"):
        h.take(east)


def test_misuse_is_refused_with_a_sentence():
    task = task_of("demo")
    h = task.open(Variant("greedy", ()), task.episodes[0], 0)
    with pytest.raises(RuntimeError, match="no decision is pending"):
        h.answer(None)
    with pytest.raises(RuntimeError, match="has not ended"):
        h.result()
    with pytest.raises(RuntimeError, match="start\\(primitive=True\\)"):
        h.take(lambda st: 0.0)
    h.start()
    with pytest.raises(RuntimeError, match="started already"):
        h.start()
    res = h.play()
    with pytest.raises(RuntimeError, match="the episode has ended"):
        h.answer(None)
    assert res is h.result()


def test_a_kind_of_before_0_4_runs_with_a_warning():
    """A kind (here one that extends door search, as another package would) whose own
    ``episode(..., decide)`` answers its decisions: registered with a DeprecationWarning naming the
    replacement and the releases; the batch calls that episode (its record shows it) and makes the
    run as before; it cannot be stepped from outside."""

    class OldDoors(DoorTask):
        kind = "doors_before_0_4"

        def episode(self, state, planner, goal, rng, observer=None, decide=None):
            state.belief = self.new_belief()
            search = DoorSearch(self, planner, goal, rng, observer)
            out = run_loop(search, state, self.sc.robot.step, self.sc.experiment.max_distance, self.max_steps(), decide=decide)
            return Outcome(out, state.distance, state.steps, search.decisions, record={"mine": 1}), state

    with pytest.warns(DeprecationWarning, match=r"episode\(\.\.\., decide\) answers its own decisions.*since semsearch "
                      r"0\.4\.0 and will be removed in 0\.5\.0: write its steps"):
        register_task(OldDoors)
    try:
        task = task_of("demo")
        old = OldDoors(task.sc, task.world, task.path)
        old.shortest, old._episodes = task.shortest, task.episodes
        v, ep = Variant("greedy", ()), task.episodes[0]
        res = old.run(v, ep, 0)
        same(res, task.run(v, ep, 0))
        assert res.record == {"mine": 1}  # its own episode ran
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(RuntimeError, match="cannot be stepped so"):
                old.open(None, ep, 0, seat=Agent()).start()
    finally:
        TASKS.pop("doors_before_0_4", None)


def test_a_kind_whose_search_returns_its_outcome_runs_with_a_warning():
    """A kind's ``search`` of before 0.4.0 runs whole and returns the Outcome (not a generator):
    registered with a warning, and its runs are made as before."""

    class OldSearch(DoorTask):
        kind = "doors_search_before_0_4"

        def search(self, variant, ep, seed, st, rng, seat, observer):
            out, _ = self.episode(st, seat.planner(variant), ep.goal, rng, observer, decide=seat.decide)
            return out

    with pytest.warns(DeprecationWarning, match=r"search\(\) runs whole and returns its Outcome.*0\.5\.0"):
        register_task(OldSearch)
    try:
        task = task_of("demo")
        old = OldSearch(task.sc, task.world, task.path)
        old.shortest, old._episodes = task.shortest, task.episodes
        v, ep = Variant("nsos", (("alpha", 0.9),)), task.episodes[1]
        same(old.run(v, ep, 2), task.run(v, ep, 2))
    finally:
        TASKS.pop("doors_search_before_0_4", None)


def test_episode_takes_the_kinds_own_options():
    """``Task.episode`` (the planner answering) passes a kind's own options on to its ``steps``:
    door search's ``reuse_reads``."""
    task = task_of("demo")
    st = task.start_state(task.episodes[0], np.random.default_rng(0))
    out, st = task.episode(st, Variant("greedy", ()).build(), 304, np.random.default_rng(1), reuse_reads=True)
    assert out.outcome == "found" and out.decisions > 0


def test_a_chain_is_opened_and_stepped_through_all_its_stages(tmp_path):
    """A chain's run meets the decisions of its stages, kept and from scratch, in the order they
    run; stepped from outside it is the batch's run, its stage rows too."""
    chain = Loaded.load(TASKS["chain"].example(tmp_path / "chain", "greedy")).task
    v, ep = Variant("greedy", ()), chain.episodes[0]
    batch = chain.run(v, ep, 1)
    h = chain.open(v, ep, 1)
    point, n = h.start(), 0
    while isinstance(point, DecisionPoint):
        point = h.answer(point.ask())
        n += 1
    same(h.result(), batch)
    assert len(h.result().stages) == len(batch.stages) > 2 and n > batch.decisions
    drop = lambda rows: [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]  # noqa: E731
    assert drop(h.rows()) == drop(chain.rows(v, ep, 1, batch))


def test_compass_step_still_counts_the_step_and_compass_move_leaves_it_to_the_episode():
    """An environment of before 0.4.0 that steps its robot itself keeps ``compass_step`` (the step
    counted); the built-in ones move with ``compass_move`` and let ``OpenEpisode.take`` count."""
    task = task_of("demo")
    w = task.world
    a, b = task.start_state(task.episodes[0], np.random.default_rng(0)), task.start_state(task.episodes[0], np.random.default_rng(0))
    assert compass_step(a, 0, 0.1, w.cspace, w.frame) == compass_move(b, 0, 0.1, w.cspace, w.frame) == 0.1
    assert (a.x, a.y, a.heading) == (b.x, b.y, b.heading)
    assert (a.steps, a.distance, len(a.trail)) == (1, 0.1, 2) and (b.steps, b.distance, len(b.trail)) == (0, 0.0, 1)
