"""Runs replay from their decisions: every built-in planner of every kind, on the golden scenarios,
recorded with ``--decisions`` and replayed without its planner, gives the rows it gave, exactly;
``semsearch verify`` names a run that does not replay."""

import json
import shutil
import textwrap

import gymnasium as gym
import semsearch_cli.envs  # noqa: F401  (registers the environments)
import pandas as pd
import pytest
from typer.testing import CliRunner

from semsearch_cli import api
from semsearch_cli.cli import app
from semsearch_cli.planners import Variant
from semsearch_cli.runner import BatchOptions, Loaded, RunSpec, file_stem, run_batch
from semsearch_cli.runner.verify import verify_folder
from semsearch_cli.tasks import TASKS
from semsearch_cli.tasks.decisions import Recording, Replay, ReplayError
from tests.golden.cases import CASES, FILE, IGNORED, ROOT, planners


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """The golden cases run with their decisions recorded, one folder per config; and the chain
    kind's example (doors 452, 304, 452 again), greedy and nsos, two repeats."""
    out = tmp_path_factory.mktemp("recorded")
    folders = {}
    for config, kind, episodes, repeats in CASES:
        L = Loaded.load(ROOT / "configs" / f"{config}.yaml")
        specs = [RunSpec(L.task.episodes[k], v, s) for v in planners(kind) for k in episodes for s in repeats]
        run_batch(L, specs, out / config, BatchOptions(workers=1, decisions=True))
        folders[config] = (out / config, L)
    chain = TASKS["chain"].example(out / "chain_src", "greedy")
    L = Loaded.load(chain)
    specs = [RunSpec(L.task.episodes[0], v, s) for v in (Variant("greedy", ()), Variant("nsos", (("alpha", 0.9),)))
             for s in (0, 1)]
    run_batch(L, specs, out / "chain", BatchOptions(workers=1, decisions=True))
    folders["chain"] = (out / "chain", L)
    return folders


def test_recording_the_decisions_moves_no_golden_row(recorded):
    want = pd.read_csv(FILE, dtype=str, keep_default_na=False)
    got = pd.concat([pd.read_csv(recorded[c][0] / "runs.csv", dtype=str, keep_default_na=False) for c, *_ in CASES],
                    ignore_index=True).drop(columns=list(IGNORED)).fillna("")  # a column one folder lacks: empty
    got = got.sort_values(["scenario", "planner", "goal", "episode", "seed", "stage"], kind="stable").reset_index(drop=True)
    assert got.equals(want)


@pytest.mark.parametrize("config", [c for c, *_ in CASES] + ["chain"])
def test_every_built_in_planner_replays_exactly_from_its_decisions(recorded, config):
    folder, _ = recorded[config]
    verdict = verify_folder(folder, Loaded.load(recorded[config][1].path, planners=False))
    assert verdict.failed == [] and verdict.unrecorded == 0
    assert verdict.verified == verdict.runs == len(list((folder / "decisions").glob("*.json")))
    if config == "chain":  # stage rows compared too: 2 planners x 2 repeats x (1 + 3 stages x kept/scratch)
        assert len(pd.read_csv(folder / "runs.csv")) == 4 * 7


def test_a_path_that_reuses_the_planners_search_replays(tmp_path):
    """nsos searches the belief from the robot to every candidate, and the path to the target it
    chose reuses that search; the record keeps the search (``left``) so that the replay, with no
    planner, plans the same path. Hospital chain night, episode 3: a replay that searched afresh
    took another path at one of its 2,082 re-plans."""
    L = Loaded.load(ROOT / "configs" / "hospital.yaml")
    ep = next(e for e in L.task.episodes if str(e.goal) == "night")
    specs = [RunSpec(ep, Variant("nsos", (("alpha", 0.9),)), s) for s in (0, 1)]
    run_batch(L, specs, tmp_path / "r", BatchOptions(workers=1, decisions=True))
    records = [json.loads(f.read_text()) for f in sorted((tmp_path / "r" / "decisions").glob("*.json"))]
    assert all(len(r["left"]) > 0.9 * len(r["decisions"]) for r in records)  # nsos leaves its search at nearly every decision
    verdict = verify_folder(tmp_path / "r", Loaded.load(L.path, planners=False))
    assert (verdict.verified, verdict.failed) == (2, [])


def test_the_verdict_is_the_same_in_one_process_or_two(recorded, tmp_path):
    folder = tmp_path / "demo"
    shutil.copytree(recorded["demo"][0], folder)
    f = folder / "decisions" / "nsos_alpha0.9__goal304__ep0__seed1.json"
    d = json.loads(f.read_text())
    d["decisions"][0] = [1, 1]  # a wall: the replay stops there
    f.write_text(json.dumps(d))
    loaded = Loaded.load(recorded["demo"][1].path, planners=False)
    one, two = verify_folder(folder, loaded, workers=1), verify_folder(folder, loaded, workers=2)
    runs = len(planners("doors")) * 2 * 2  # every built-in door planner x 2 episodes x 2 repeats
    assert one == two and one.runs == runs and one.verified == runs - 1
    assert [n for n, _ in one.failed] == ["nsos[alpha=0.9] goal 304 episode 0 seed 1"]


def test_a_decision_costs_a_few_bytes(recorded):
    folder, _ = recorded["hospital"]
    sizes = []
    for f in (folder / "decisions").glob("*.json"):
        d = json.loads(f.read_text())
        sizes.append(len(json.dumps(d["decisions"], separators=(",", ":"))) / len(d["decisions"]))
    assert max(sizes) < 12  # [412,1033] (a 0 for a re-plan that asks the same), beside the search kept in "left"


def test_the_replay_is_the_run_path_and_all(recorded):
    folder, L = recorded["indirect_quick"]
    ep, v = L.task.episodes[139], Variant("ISUP", ())  # a planner that draws from the generator at every decision
    rec = Recording()
    a = L.task.run(v, ep, 0, seat=rec)
    record = json.loads(json.dumps(rec.record("indirect")))
    assert len(record["rng"]) == len(record["decisions"]) > 5
    b = L.task.run(v, ep, 0, seat=Replay(record))
    assert (a.outcome, a.distance_m, a.steps, a.decisions) == (b.outcome, b.distance_m, b.steps, b.decisions)
    assert (a.path == b.path).all()
    short = {**record, "decisions": record["decisions"][:3]}
    with pytest.raises(ReplayError, match="the record holds 3"):
        L.task.run(v, ep, 0, seat=Replay(short))


def test_verify_names_a_run_whose_decisions_or_rows_were_changed(recorded, tmp_path):
    folder = tmp_path / "demo"
    shutil.copytree(recorded["demo"][0], folder)
    f = sorted((folder / "decisions").glob("greedy__goal452__ep1__seed0.json"))[0]
    d = json.loads(f.read_text())
    d["decisions"][2] = [d["decisions"][2][0] + 9, d["decisions"][2][1]]  # another target on the third decision
    f.write_text(json.dumps(d))
    scenario = ["--scenario", str(recorded["demo"][1].path)]  # a copied folder: meta.json's relative path is lost
    res = CliRunner().invoke(app, ["verify", str(folder), *scenario])
    assert res.exit_code == 1, res.output
    assert "does not replay: greedy goal 452 episode 1 seed 0:" in res.output
    runs = len(planners("doors")) * 2 * 2  # every built-in door planner x 2 episodes x 2 repeats
    assert f"{runs - 1} of {runs} runs replayed" in res.output

    (folder / "decisions").rename(tmp_path / "gone")
    res = CliRunner().invoke(app, ["verify", str(folder), *scenario])
    assert res.exit_code == 2 and "has a decisions record: run the batch with --decisions" in res.output


def test_a_planner_whose_code_is_gone_is_verified_by_its_decisions(tmp_path):
    """A planner of one's own that draws from the run's generator: recorded with ``semsearch run
    --decisions``, its file deleted, and the results verified without it."""
    src = TASKS["doors"].example(tmp_path / "s", "greedy")
    (src.parent / "coin.py").write_text(textwrap.dedent('''
        from semsearch_cli.planners import Decision, DoorPlanner, register_planner

        @register_planner("verify_coin")
        class Coin(DoorPlanner):
            """A frontier candidate at random."""
            def choose(self, ctx, cands):
                if len(cands) == 0:
                    return None
                k = int(ctx.rng.integers(len(cands)))
                return Decision(int(cands.rows[k]), int(cands.cols[k]))
    '''))
    text = src.read_text().replace("name: greedy", "name: verify_coin\n  module: coin.py")
    src.write_text(text)
    out = tmp_path / "r"
    res = CliRunner().invoke(app, ["run", str(src), "--seeds", "2", "--workers", "1", "--decisions", "--out", str(out)])
    assert res.exit_code == 0, res.output
    (src.parent / "coin.py").unlink()
    verdict = api.verify(out).verdict
    assert (verdict.verified, verdict.runs, verdict.failed) == (2, 2, [])
    assert all(json.loads(f.read_text())["rng"] for f in (out / "decisions").glob("*.json"))


def test_an_environment_answers_the_batchs_decision_points(recorded):
    """The object environment's agent, answering with the places an object planner chose in the
    batch, travels what the batch recorded: the same decision points, driven another way."""
    folder, L = recorded["office"]
    rows = pd.read_csv(folder / "runs.csv")
    env = gym.make("semsearch/ObjectSearch-v0", scenario=str(L.path)).unwrapped
    checked = 0
    for _, row in rows[rows["planner"] == "brute_force"].iterrows():
        stem = file_stem("brute_force", row["goal"], int(row["seed"]), int(row["episode"]))
        items = json.loads((folder / "decisions" / f"{stem}.json").read_text())["decisions"]
        if not all(isinstance(i, list) and len(i) == 1 for i in items):
            continue  # a target that is not a place (the home): no action names it
        env.reset(options={"episode": int(row["episode"]), "repeat": int(row["seed"])})
        for (k,) in items:
            *_, info = env.step(k)
        assert (info["outcome"], info["steps"]) == (row["outcome"], row["steps"])
        assert info["distance_m"] == pytest.approx(row["distance_m"], abs=1e-3)
        checked += 1
    assert checked >= 2


# -- verify checks the folder, not only the runs that kept a record (issue 52) ---------------------

@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    """A real results folder of ``semsearch run --decisions``: greedy on the demo building, goals
    304 and 452, one repeat each (tests/hostile_bench_surface.make_results, ~2 s), and its scenario."""
    from tests.hostile_bench_surface import make_results
    return make_results(tmp_path_factory.mktemp("two_runs"))


def _tampered(two_runs, tmp_path, change):
    folder = tmp_path / "r"
    shutil.copytree(two_runs[0], folder)
    change(folder)
    return folder


def _edit(folder, edit):
    f = folder / "runs.csv"
    edit(pd.read_csv(f, dtype=str, keep_default_na=False)).to_csv(f, index=False)


def _cell(col, value):
    def edit(r):
        r.loc[0, col] = value
        return r
    return lambda d: _edit(d, edit)


RUN0 = "greedy__goal304__ep0__seed0.json"
TAMPERED = {  # each tampering -> what the verdict names (the first run is greedy goal 304 episode 0 seed 0)
    "a record deleted": (lambda d: (d / "decisions" / RUN0).unlink(), "which the row names (decisions_sha256), is gone"),
    "a record replaced by a folder": (lambda d: ((d / "decisions" / RUN0).unlink(), (d / "decisions" / RUN0).mkdir()),
                                      "is not a file"),
    "a row's seed edited": (_cell("seed", "5"), "a record without its row"),
    "a row added": (lambda d: _edit(d, lambda r: pd.concat([r, r.iloc[[0]].assign(seed="2")], ignore_index=True)),
                    "seed 2: its record"),
    "a row duplicated": (lambda d: _edit(d, lambda r: pd.concat([r, r.iloc[[0]]], ignore_index=True)), "appears 2 times"),
    "a row deleted": (lambda d: _edit(d, lambda r: r.iloc[1:]), "a record without its row"),
    "5.0 m and its record deleted": (lambda d: (_cell("distance_m", "5.0")(d), (d / "decisions" / RUN0).unlink()), "is gone"),
    "a row of no episode": (_cell("episode", "7"), "no episode 7 of goal 304"),
    "a record of the other run": (lambda d: (shutil.copyfile(d / "decisions" / "greedy__goal452__ep1__seed0.json",
                                                             d / "decisions" / RUN0), _cell("decisions_sha256", "")(d)),
                                  "records another run (greedy goal 452 episode 1 seed 0)"),
}


@pytest.mark.parametrize("tampering", list(TAMPERED))
def test_a_falsified_folder_does_not_verify(two_runs, tmp_path, tampering):
    change, says = TAMPERED[tampering]
    folder = _tampered(two_runs, tmp_path, change)
    v = api.verify(folder, two_runs[1], workers=1).verdict
    assert v.failed and any(says in f"{name}: {why}" for name, why in v.failed), v.failed


def test_verify_exits_1_naming_a_run_whose_record_was_taken_away(two_runs, tmp_path):
    folder = _tampered(two_runs, tmp_path, lambda d: (d / "decisions" / RUN0).unlink())
    res = CliRunner().invoke(app, ["verify", str(folder), "--scenario", str(two_runs[1]), "--workers", "1"])
    assert res.exit_code == 1, res.output
    assert "does not replay: greedy goal 304 episode 0 seed 0: its record" in " ".join(res.output.split())


def test_rows_recorded_with_decisions_name_their_record_and_allow_unrecorded_counts_the_rest(two_runs, tmp_path):
    import hashlib
    rows = pd.read_csv(two_runs[0] / "runs.csv", dtype=str)
    files = sorted((two_runs[0] / "decisions").glob("*.json"))
    assert sorted(rows["decisions_sha256"]) == sorted(hashlib.sha256(f.read_bytes()).hexdigest() for f in files)
    # a folder recorded partly without --decisions: a row without a record, naming none
    folder = _tampered(two_runs, tmp_path, lambda d: ((d / "decisions" / RUN0).unlink(), _cell("decisions_sha256", "")(d)))
    strict = api.verify(folder, two_runs[1], workers=1).verdict
    assert [n for n, _ in strict.failed] == ["greedy goal 304 episode 0 seed 0"]
    loose = api.verify(folder, two_runs[1], workers=1, allow_unrecorded=True).verdict
    assert (loose.failed, loose.unrecorded, loose.verified) == ([], 1, 1)
    res = CliRunner().invoke(app, ["verify", str(folder), "--scenario", str(two_runs[1]), "--workers", "1", "--allow-unrecorded"])
    assert res.exit_code == 0 and "1 without decisions not checked" in res.output
    _cell("distance_m", "5.0")(folder)  # and it claims less than the shortest path (11.7 m): no run does that
    loose = api.verify(folder, two_runs[1], workers=1, allow_unrecorded=True).verdict
    assert "below its episode's shortest path" in loose.failed[0][1]


def test_an_honest_folder_with_error_rows_verifies(tmp_path):
    """A planner that raises leaves error rows and no record (the run did not finish): they are
    counted, and the folder verifies."""
    src = TASKS["doors"].example(tmp_path / "s", "greedy")
    (src.parent / "boom.py").write_text(textwrap.dedent('''
        from semsearch_cli.planners import DoorPlanner, register_planner

        @register_planner("verify_boom")
        class Boom(DoorPlanner):
            """Raises at its first decision."""
            def choose(self, ctx, cands):
                raise RuntimeError("boom")
    '''))
    src.write_text(src.read_text().replace("name: greedy", "name: greedy\n- name: verify_boom\n  module: boom.py"))
    out = tmp_path / "r"
    res = CliRunner().invoke(app, ["run", str(src), "--seeds", "1", "--workers", "1", "--decisions", "--out", str(out)])
    assert res.exit_code == 0, res.output
    rows = pd.read_csv(out / "runs.csv")
    assert set(rows.loc[rows["planner"] == "verify_boom", "outcome"]) == {"error"}
    res = CliRunner().invoke(app, ["verify", str(out), "--workers", "1"])
    assert res.exit_code == 0, res.output
    n = int((rows["planner"] == "verify_boom").sum())
    assert f"{n} error or timeout run(s) not replayed" in " ".join(res.output.split())
