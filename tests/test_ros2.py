"""Runs exported as ROS 2 bags (`semsearch export`), read back without ROS: rosbags for the
messages, the mcap library for the file (its chunks' checksums)."""

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("rosbags", reason="the ros extra (rosbags) is not installed")
mcap_reader = pytest.importorskip("mcap.reader", reason="the ros extra (mcap) is not installed")
from rosbags.rosbag2 import Reader  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

from semsearch_cli.cli import app  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.ros2 import TOPICS  # noqa: E402
from semsearch_cli.runner import BatchOptions, Loaded, RunSpec, run_batch  # noqa: E402
from semsearch_cli.tasks import TASKS  # noqa: E402
from semsearch_cli.tasks.base import Observer  # noqa: E402
from semsearch_cli.tasks.decisions import Replay  # noqa: E402
from semsearch_cli.runner.store import read_decisions  # noqa: E402

TS = get_typestore(Stores.ROS2_HUMBLE)
RUN = "greedy__goal452__ep0__seed0"


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """The demo building, goal 452, greedy and nsos, one seed each, decisions recorded."""
    out = tmp_path_factory.mktemp("ros2")
    scenario = TASKS["doors"].example(out / "src", "greedy")
    L = Loaded.load(scenario)
    specs = [RunSpec(L.task.episodes[0], v, 0) for v in (Variant("greedy", ()), Variant("nsos", (("alpha", 0.9),)))]
    runs = run_batch(L, specs, out / "results", BatchOptions(workers=1, decisions=True))
    return out, L, runs, scenario


def messages(bag):
    """{topic: [(stamp ns, message)]} of a bag folder."""
    out = {}
    with Reader(bag) as r:
        for c, t, raw in r.messages():
            out.setdefault(c.topic, []).append((t, TS.deserialize_cdr(raw, c.msgtype)))
    return out


class Final(Observer):
    """The belief and reads as a run ends (the last step it shows)."""

    steps = True

    def __init__(self):
        self.last = None
        self.reads = []

    def see(self, event):
        if hasattr(event, "reads") and hasattr(event, "scan"):
            self.last = event
            self.reads += list(event.reads)


@pytest.mark.parametrize("fmt", ["mcap", "rosbag2"])
def test_a_run_exports_as_a_bag_that_reads_back_step_for_step(recorded, fmt):
    out, L, runs, scenario = recorded
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / fmt), "--format", fmt, "--run", RUN,
                                   "--scenario", str(scenario)])
    assert res.exit_code == 0, res.output
    assert "1 bag(s) written" in res.output
    bag = out / fmt / RUN
    row = runs[runs["planner"] == "greedy"].iloc[0]
    got = messages(bag)
    assert set(got) == set(TOPICS)
    steps, decisions = int(row["steps"]), int(row["decisions"])
    # every step (the start's frame too) has its pose, /tf and scan; every decision its target and frontiers
    for topic in ("/semsearch/pose", "/tf", "/scan"):
        assert len(got[topic]) == steps + 1
    for topic in ("/semsearch/goal", "/explore/frontiers", "/semsearch/decision"):
        assert len(got[topic]) == decisions
    assert len(got["/map"]) == decisions + 2 and 2 <= len(got["/semsearch/path"]) <= decisions + 1
    # stamps: simulated time, 0.2 s a step (0.1 m at 0.5 m/s), in order
    stamps = [t for t, _ in got["/semsearch/pose"]]
    assert stamps[0] == 1_000_000_000 and np.all(np.diff(stamps) == 200_000_000)
    # the same run, replayed here with an observer: its poses, reads and final map are the bag's
    fin = Final()
    ep = L.task.episodes[0]
    record = read_decisions(out / "results" / "decisions" / f"{RUN}.json")
    rerun = L.task.run(Variant("greedy", ()), ep, 0, observer=fin, seat=Replay(record))
    trail = np.asarray(rerun.path, float)
    poses = np.array([[m.pose.position.x, m.pose.position.y] for _, m in got["/semsearch/pose"]])
    assert np.allclose(poses[1:], trail[1:], atol=1e-5) and np.allclose(poses[0], trail[0], atol=1e-5)
    path = np.array([[p.pose.position.x, p.pose.position.y] for p in got["/semsearch/path"][-1][1].poses])
    assert np.allclose(path, np.vstack([trail[::5], trail[-1:]]) if (len(trail) - 1) % 5 else trail[::5], atol=1e-5)  # every 0.5 m
    last = got["/semsearch/pose"][-1][1].pose.orientation
    assert math.isclose(2 * math.atan2(last.z, last.w), fin.last.heading, abs_tol=1e-9)
    grid = got["/map"][-1][1]
    b, fr = fin.last.belief, L.world.frame
    rr, cc = np.nonzero(b.seen)
    H, W = int(rr.max() - rr.min() + 1), int(cc.max() - cc.min() + 1)
    assert (grid.info.height, grid.info.width) == (H, W) and math.isclose(grid.info.resolution, fr.res, rel_tol=1e-6)
    data = grid.data.reshape(H, W)[::-1]  # back to the simulator's rows (row 0 at the top)
    sub = (slice(rr.min(), rr.max() + 1), slice(cc.min(), cc.max() + 1))
    want = np.where(b.seen[sub], np.where(b.free[sub], 0, 100), -1)
    assert np.array_equal(data, want)
    x0, y0 = fr.to_world(rr.max(), cc.min())  # the centre of the grid's first cell (lowest row, first column)
    assert math.isclose(grid.info.origin.position.x + fr.res / 2, x0, abs_tol=1e-6)
    assert math.isclose(grid.info.origin.position.y + fr.res / 2, y0, abs_tol=1e-6)
    # a detection per read, at the sign's position, with its label; the goal was read last
    det = [json.loads(m.data) for _, m in got["/semsearch/detections"]]
    assert len(det) == len(fin.reads) > 0
    s = L.world.signs
    for d, (i, label) in zip(det, fin.reads):
        assert d["label"] == str(label) and (d["x"], d["y"], d["facing"]) == (float(s.x[i]), float(s.y[i]), float(s.facing[i]))
    assert det[-1]["label"] == "452"
    # scans in m, +inf where a beam returned nothing, within the laser's range
    scan = got["/scan"][0][1]
    finite = scan.ranges[np.isfinite(scan.ranges)]
    assert scan.range_max == L.sc.laser.range and finite.size and finite.max() <= scan.range_max + 1e-4
    assert math.isclose(scan.angle_max - scan.angle_min, math.radians(L.sc.laser.fov), abs_tol=1e-6)  # float32 fields
    # the chosen target is among the frontiers of its decision, drawn larger
    for (_, goal), (_, fronts) in zip(got["/semsearch/goal"], got["/explore/frontiers"]):
        spheres = [m for m in fronts.markers if m.action == 0]
        big = [m for m in spheres if m.scale.x == 0.5]
        assert len(big) == 1 and math.isclose(big[0].pose.position.x, goal.pose.position.x, abs_tol=1e-9)


def test_the_mcap_file_checks_out_with_the_mcap_library(recorded):
    out, _, _, scenario = recorded
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / "all"), "--scenario", str(scenario)])
    assert res.exit_code == 0, res.output
    bags = sorted(b for b in (out / "all").iterdir() if not b.name.startswith("."))  # not the folder's lock
    assert {b.name for b in bags} == {RUN, "nsos_alpha0.9__goal452__ep0__seed0"}
    for bag in bags:
        files = list(bag.glob("*.mcap"))
        assert len(files) == 1 and files[0].stem == bag.name
        with open(files[0], "rb") as fh:
            reader = mcap_reader.make_reader(fh, validate_crcs=True)
            n = sum(1 for _ in reader.iter_messages())
            summary = reader.get_summary()
        assert n == summary.statistics.message_count > 0
        assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
        assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
        assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
    again = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(out / "all"), "--scenario", str(scenario)])
    assert again.exit_code == 0 and "0 bag(s) written" in again.output  # kept, not written twice


def test_export_errors_name_the_flag_and_leave_no_bag(recorded, tmp_path):
    out, _, _, scenario = recorded
    cases = [(["--run", "greedy__goal452__ep0__seed9"], "did you mean 'greedy__goal452__ep0__seed0'"),
             (["--format", "bag"], "use one of mcap, rosbag2")]
    for extra, says in cases:
        res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(tmp_path / "x"), "--scenario", str(scenario),
                                       *extra])
        assert res.exit_code == 2 and says in " ".join(res.output.split()), res.output
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "runs.csv").write_text((out / "results" / "runs.csv").read_text())  # rows without their decisions
    res = CliRunner().invoke(app, ["export", str(bare), "--out", str(tmp_path / "y"), "--scenario", str(scenario)])
    assert res.exit_code == 2 and "no run of this folder has a decisions record" in " ".join(res.output.split())
    assert not [p for p in (tmp_path / "y").rglob("*") if not p.name.startswith(".")]  # nothing but the folder's lock
    # another scenario than the rows': the replay goes elsewhere, and no bag (nor a partial one) is left
    other = scenario.with_name("other.yaml")
    other.write_text(scenario.read_text() + "laser: {range: 4.0}\n")
    res = CliRunner().invoke(app, ["export", str(out / "results"), "--out", str(tmp_path / "z"), "--scenario", str(other),
                                   "--run", RUN])
    said = " ".join(res.output.split())
    assert res.exit_code == 2 and ("does not replay" in said or "not the row's" in said), res.output
    assert not [p for p in (tmp_path / "z").rglob("*") if p.name != ".semsearch.lock"]
