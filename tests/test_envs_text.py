"""The action mask and the text observation of the Gymnasium environments (semsearch_cli.envs):
``info["action_mask"]`` is int8, as ``action_space.sample(mask)`` takes it, and ``action_masks()``
bool, as sb3-contrib's MaskablePPO takes it; the text says which frame its positions and angles are
in, and its answer line offers exactly the actions the mask allows."""

import re
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from semsearch_cli.envs.base import TEXT_CHARSET, TEXT_LENGTH, clip_text  # noqa: E402
from semsearch_cli.planners.text import ANGLES_TEXT, FRAME_TEXT, deg, spell  # noqa: E402

from .test_envs import KWARGS, MODES, make  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ANSWER = re.compile(r"Answer with one number: (.+)\.")


def offered(text: str) -> list[int]:
    """The action numbers the text's answer line (its last line) offers, read back from its words
    (``0, 1 or 64``, ``0-2 or 4-9``)."""
    m = ANSWER.fullmatch(text.rsplit("\n", 1)[-1])
    assert m, text.rsplit("\n", 1)[-1]
    out = []
    for item in re.split(r", | or ", m.group(1)):
        a, _, b = item.partition("-")
        out += range(int(a), int(b or a) + 1)
    return out


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", sorted(KWARGS))
def test_the_info_mask_is_int8_and_samples_only_valid_actions(env_id, mode):
    env = make(env_id, action_mode=mode)
    env.action_space.seed(0)
    _, info = env.reset(seed=0)
    for _ in range(4):  # the reset and three steps (an object search masks the place just looked at)
        mask = info["action_mask"]
        assert mask.dtype == np.int8 and mask.shape == (env.action_space.n,)
        bools = env.unwrapped.action_masks()
        assert bools.dtype == bool and np.array_equal(bools, mask.astype(bool))
        drawn = {int(env.action_space.sample(mask)) for _ in range(300)}  # the idiom
        assert drawn <= set(np.flatnonzero(mask).tolist())
        if mask.sum() <= 10:
            assert drawn == set(np.flatnonzero(mask).tolist())
        _, _, term, trunc, info = env.step(max(drawn))
        if term or trunc:
            break


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", sorted(KWARGS))
def test_the_text_states_its_frame_and_offers_exactly_the_valid_actions(env_id, mode):
    env = make(env_id, action_mode=mode, observation_mode="text")
    obs, info = env.reset(seed=0)
    for _ in range(4):
        assert ("Frame: x points east and y north, in metres" in obs and ANGLES_TEXT in obs and "leading" not in obs)
        assert set(obs) <= TEXT_CHARSET and len(obs) <= TEXT_LENGTH
        valid = np.flatnonzero(info["action_mask"]).tolist()
        assert offered(obs) == valid
        if not (env_id.startswith("semsearch/IndirectSearch") and mode == "macro"):
            shown = {int(n) for n in re.findall(r"(?:^|: |; )\[(\d+)\]", obs, re.M)}
            assert set(valid) <= shown  # every valid answer is explained, as [n]
        obs, _, term, trunc, info = env.step(valid[-1])
        if term or trunc:
            break


def test_a_seeded_door_reset_reads_as_pinned():
    """The issue's case: one frontier target, and the sweep (64) the mask also allows."""
    env = make("semsearch/DoorSearch-Hotel-v0", observation_mode="text")
    obs, info = env.reset(seed=1)
    assert obs == (
        "Goal: read the door sign 135.\n"
        + FRAME_TEXT + "\n"
        "You are at x 111.8 m, y 50.5 m, heading 30 deg; travelled 0.0 m.\n"
        "Signs read, nearest first (facing: the direction the sign's face points): 94 at 1.7 m, bearing -64 deg, "
        "facing 90 deg.\n"
        "Choices: drive to a frontier target (a point on the edge of the explored area), nearest first, with the "
        "direction in which unexplored space goes on beyond it; or look at a wall:\n"
        "[0] 1.2 m away, bearing -9 deg, unexplored space towards -21 deg\n"
        "[64] look at the nearest wall face no camera has read yet\n"
        "Answer with one number: 0 or 64.")
    assert np.flatnonzero(info["action_mask"]).tolist() == [0, 64]


def test_a_seeded_v1_door_reset_reads_as_the_llm_planner_reads_it():
    """v1: the llm planner's text (path lengths, the wall numbered after the last target)."""
    env = make("semsearch/DoorSearch-Hotel-v1", observation_mode="text")
    obs, info = env.reset(seed=1)
    assert obs == (
        "Goal: read the door sign 135.\n"
        "Frame: x points east and y north, in metres; a target's distance is the length of the robot's path to it, "
        "every other distance a straight line. " + ANGLES_TEXT + "\n"
        "You are at x 111.8 m, y 50.5 m, heading 30 deg; travelled 0.0 m.\n"
        "No sign read yet.\n"
        "Targets: frontier points on the edge of the explored area, nearest first along the path, each with the "
        "direction in which unexplored space goes on beyond it, or look at a wall:\n"
        "[0] 1.4 m along the path, bearing -9 deg, unexplored space towards -21 deg\n"
        "[1] look at the nearest wall face no camera has read yet\n"
        "Answer with one number: 0 or 1.")
    assert np.flatnonzero(info["action_mask"]).tolist() == [0, 1]


def test_the_answer_lines_of_the_other_kinds_on_seeded_cases():
    env = make("semsearch/DoorSearch-v1", action_mode="primitive", observation_mode="text")
    obs, _ = env.reset(seed=0)
    assert obs.splitlines()[-2:] == [
        "Moves (a move into a wall leaves you where you are): [0] 0.1 m east; [1] 0.1 m north-east; [2] 0.1 m north; "
        "[3] 0.1 m north-west; [4] 0.1 m west; [5] 0.1 m south-west; [6] 0.1 m south; [7] 0.1 m south-east; "
        "[8] turn 45 deg left (counter-clockwise); [9] turn 45 deg right.",
        "Answer with one number: 0-9."]
    env = make("semsearch/ObjectSearch-Office-v0", observation_mode="text")
    env.reset(seed=0)
    obs, *_ = env.step(2)  # drive to place C and look around there: C is masked next
    assert obs.splitlines()[-2:] == ["[2] C is left out: you have just looked around there.",
                                     "Answer with one number: 0, 1 or 3-9."]
    env = make("semsearch/IndirectSearch-Quick-v0", observation_mode="text")
    obs, _ = env.reset(seed=0)
    assert obs.splitlines()[-1] == "Answer with one number: 0-1151."
    assert "point k = i + 12 j is at x = 0.25 + 0.5 i m, y = 0.25 + 0.5 j m (i 0-11, j 0-11)" in obs
    u = env.unwrapped  # the quick rooms have no obstacle on the lattice: take points 0, 1 and 13 away
    u.standable[[0, 1, 13]] = False
    assert u._observe().splitlines()[-1] == "Answer with one number: 16-103 or 112-1151."
    assert np.flatnonzero(~u.action_masks()).tolist() == [*range(16), *range(104, 112)]
    env = make("semsearch/IndirectSearch-Quick-v0", action_mode="primitive", observation_mode="text")
    obs, _ = env.reset(seed=0)
    assert obs.splitlines()[-2:] == [
        "Choices (each takes one camera frame, 0.33 s): [0] drive 0.0667 m forward, along your heading (not into an "
        "obstacle); [1] turn 13.3 deg left (counter-clockwise); [2] turn 13.3 deg right; [3] wait.",
        "Answer with one number: 0-3."]


@pytest.mark.parametrize("numbers,words", [([], "none"), ([3], "3"), ([0, 1], "0 or 1"), ([0, 1, 64], "0, 1 or 64"),
                                           ([0, 1, 2, 4, 5, 6, 7, 8, 9], "0-2 or 4-9"),
                                           ([*range(8, 88), *range(104, 184), 200], "8-87, 104-183 or 200")])
def test_spell_names_action_numbers_in_runs(numbers, words):
    assert spell(numbers) == words


def test_deg_gives_whole_degrees_in_the_half_open_circle():
    assert [deg(np.radians(d)) for d in (0, -0.3, 90, 179.6, 180, -180, -90, 359.7, 405)] == \
        ["0", "0", "90", "180", "180", "180", "-90", "0", "45"]


def test_a_clipped_text_keeps_its_answer_line():
    text = clip_text("x" * 9000 + "\nAnswer with one number: 0-9.")
    assert len(text) == TEXT_LENGTH and text.endswith("x\n...\nAnswer with one number: 0-9.")
    assert clip_text("short\ttext") == "short?text"


def test_the_text_observation_on_the_environments_page_is_a_real_run(capsys, monkeypatch):
    """docs/environments.md shows a text observation and the code that prints it: they agree."""
    page = (ROOT / "docs" / "environments.md").read_text()
    part = page.split("## Text observations", 1)[1]
    code = part.split("```python\n", 1)[1].split("```", 1)[0]
    shown = part.split("```text\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(ROOT)
    exec(compile(code, "environments.md", "exec"), {})
    assert capsys.readouterr().out == shown
