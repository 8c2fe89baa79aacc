"""Room labels with letters and separators are signs like any other: parsed into a prefix,
a number and a suffix; goals are matched on the whole label; nsos and the draft planner reason on
the numbers of the signs that share the goal's prefix."""

import numpy as np
import pandas as pd
import pytest
import yaml

from semsearch_cli.planners.doors.nsos import NSOS
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch
from semsearch_cli.world.labels import SignLabel, parse_label


@pytest.mark.parametrize("label,want", [
    (148, ("", 148, "")), ("148", ("", 148, "")), ("K202", ("K", 202, "")), ("C638", ("C", 638, "")),
    ("24D", ("", 24, "D")), ("2.14", ("2", 14, "")), ("B-105", ("B", 105, "")), ("3-107a", ("3", 107, "a")),
    ("A9A", ("A", 9, "A")), ("2512/2", ("", 2512, "/2")), ("Lab", None), ("Kitchen", None), (-5, None)])
def test_labels_are_read_as_prefix_number_suffix(label, want):
    assert parse_label(label) == (SignLabel(*want) if want else None)


def relabelled(demo_dir, tmp_path, rename, goals, planners):
    doors = pd.read_csv(demo_dir / "doors.csv")
    doors["number"] = [rename(int(n)) for n in doors["number"]]
    doors.to_csv(tmp_path / "doors.csv", index=False)
    d = yaml.safe_load((demo_dir / "scenario.yaml").read_text())
    d.update(name="labels", doors=str(tmp_path / "doors.csv"), goals=goals, planners=planners)
    d["map"]["image"] = str(demo_dir / "map.png")
    d["experiment"]["seeds"] = 3
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(d))
    loaded = Loaded.load(p)
    return run_batch(loaded, expand(loaded), tmp_path / "out", BatchOptions(workers=1))


PLANNERS = [{"name": "nsos", "alpha": 0.9}, {"name": "draft"}]


def test_the_semantic_terms_read_the_numbers_of_the_goals_prefix():
    """nsos's terms of a door list: the same for K301, K303, K305 and goal K304 as for 301, 303, 305
    and goal 304; signs of another prefix (302A's prefix is empty) or with no number are left out,
    and 24D counts as 24 among the unprefixed signs."""
    nsos = NSOS(NSOS.Params())
    xy = [(1.0, 0.0), (3.0, 0.0), (5.0, 0.0)]
    plain = {n: (2, x, y) for n, (x, y) in zip((301, 303, 305), xy)}
    lettered = {f"K{n}": (2, x, y) for n, (x, y) in zip((301, 303, 305), xy)}
    mixed = {**lettered, "302A": (2, 2.0, 0.0), "Lab": (2, 4.0, 0.0)}
    want = nsos._segment_terms(plain, parse_label(304))
    for lst in (lettered, mixed):
        got = nsos._segment_terms(lst, parse_label("K304"))
        for a, b in zip(got, want):
            np.testing.assert_array_equal(a, b)
    suffixed = {"24D": (2, 1.0, 0.0), 26: (2, 3.0, 0.0)}
    for a, b in zip(nsos._segment_terms(suffixed, parse_label(25)), nsos._segment_terms({24: (2, 1.0, 0.0), 26: (2, 3.0, 0.0)},
                                                                                        parse_label(25))):
        np.testing.assert_array_equal(a, b)


def test_a_floor_of_mixed_labels_is_searched_on_the_goals_prefix(demo_dir, tmp_path):
    """Odd doors K201, K203, ...; even doors 202A, 204A, ...: nsos finds a goal of each kind, and
    its semantic terms count only the signs that share the goal's prefix."""
    rows = relabelled(demo_dir, tmp_path, lambda n: f"K{n}" if n % 2 else f"{n}A", ["K303", "452A"], PLANNERS)
    assert (rows["outcome"] == "found").all(), rows[["planner", "goal", "outcome"]]
    assert set(rows["goal"].astype(str)) == {"K303", "452A"}


def test_a_floor_labelled_k201_k202_24a_24b_is_searched_by_nsos(demo_dir, tmp_path):
    """The demo floor's west doors labelled K101 ... K204 and its wings 24A-24D, 25A-25D, 26A-26D,
    27A-27D (rooms beside one number): nsos and the draft planner find K202 and 24B in every run."""
    rows = relabelled(demo_dir, tmp_path, lambda n: f"K{n}" if n < 300 else f"{24 + (n - 301) // 50}{'ABCD'[(n - 1) % 50]}",
                      ["K202", "24B"], PLANNERS)
    assert (rows["outcome"] == "found").all(), rows[["planner", "goal", "outcome"]]
    assert sorted(set(rows["goal"].astype(str))) == ["24B", "K202"]


def test_a_goal_written_as_text_finds_the_sign_its_csv_writes_as_a_number(demo_dir, tmp_path):
    """``goals: ["303"]`` and the sign 303 of doors.csv are one label (config.base.sign_label): the
    run finds it, where a text goal never matched a number read by the camera and searched to the
    budget."""
    rows = relabelled(demo_dir, tmp_path, lambda n: n, ["303"], [{"name": "nsos", "alpha": 0.9}])
    assert (rows["outcome"] == "found").all(), rows[["planner", "goal", "outcome", "distance_m"]]
    assert (rows["distance_m"] < 200).all()
