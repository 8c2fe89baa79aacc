"""Replays from recorded frames: `semsearch run --frames` writes each run's replay frames, and the
report replays a run from them rather than re-running it; the frames are those a re-simulation
observes, value for value."""

import numpy as np
import pytest

from semsearch_cli import api
from semsearch_cli.planners import Variant
from semsearch_cli.report import doors as report_doors
from semsearch_cli.runner import BatchOptions, Loaded
from semsearch_cli.runner.store import read_frames, write_frames
from semsearch_cli.tasks import TASKS, FrameRecorder


def _same(a: list[dict], b: list[dict]) -> None:
    assert len(a) == len(b) > 0
    for fa, fb in zip(a, b):
        assert fa.keys() == fb.keys()
        for k in fa:
            if isinstance(fa[k], dict):
                assert fa[k] == fb[k], k
            else:
                np.testing.assert_array_equal(np.asarray(fa[k]), np.asarray(fb[k]), err_msg=k)


@pytest.mark.parametrize("kind", ["doors", "indirect"])
def test_recorded_frames_are_the_frames_a_rerun_observes(kind, tmp_path):
    path = TASKS[kind].example(tmp_path / "ex", "greedy" if kind == "doors" else "UIS")
    loaded = Loaded.load(path)
    ep = loaded.task.episodes[0]
    rec = FrameRecorder(limit=8)  # small, so that the thinning runs
    loaded.task.run(Variant("greedy" if kind == "doors" else "UIS", ()), ep, 0, rec)
    assert 4 <= len(rec.frames) <= 8 and rec.step >= 1
    write_frames(tmp_path / "f.npz", rec.frames)
    _same(rec.frames, read_frames(tmp_path / "f.npz"))


def test_the_report_replays_from_recorded_frames_without_rerunning(tmp_path, monkeypatch):
    path = TASKS["doors"].example(tmp_path / "ex", "greedy")
    out = tmp_path / "out"
    api.run(path, BatchOptions(seeds=1, workers=1, out=out, frames=True), plots=False)
    files = sorted((out / "frames").glob("*.npz"))
    assert len(files) == 1
    # the recorded frames are the re-simulated ones
    loaded = Loaded.load(path)
    rec = FrameRecorder()
    loaded.task.run(Variant("greedy", ()), loaded.task.episodes[0], 0, rec)
    _same(rec.frames, read_frames(files[0]))

    def no_rerun(*a, **k):
        raise AssertionError("the report re-ran a run whose frames were recorded")

    monkeypatch.setattr(report_doors, "_rerun", no_rerun)
    api.report([out], formats=("md", "png"), replay=True)
    text = (out / "report.md").read_text()
    assert "frames recorded" in text and list((out / "figures").glob("replay_*.gif"))
