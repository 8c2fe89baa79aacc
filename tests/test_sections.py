"""A kind takes the shared sections it declares: door search and chains the signs and their
sensors, belief and navigation; object search a map and a robot; indirect search its own section
alone. A section a kind does not take is refused, naming it; a section a kind took in 0.2.0
without using it is ignored with a DeprecationWarning, and the scenario's fingerprint is the one
0.2.0 gave (a results folder of 0.2.0 resumes)."""

import re
import subprocess
import sys
import warnings

import pytest
import yaml
from packaging.version import Version  # matplotlib's dependency

from semsearch_cli import __version__, api
from semsearch_cli.config import KINDS, SIGN_SECTIONS, load_scenario
from semsearch_cli.errors import ScenarioError
from semsearch_cli.runner import Loaded
from semsearch_cli.tasks import TASKS

# fingerprints of the shipped scenarios of the kinds that retired sections, on engine 2 (0.2.0, engine 1, gave
# 2f70e334ad6ad30e, 987ee939ae4e643b and 6b04a38e89d69e98: the engine is part of the fingerprint from engine 2 on)
FINGERPRINTS = {"office": "65cc8363e7d26bd9", "indirect_quick": "98f4c46f71a669cd", "indirect": "f8f7d755ac3d3019"}  # engine 2


def test_each_kind_takes_the_sections_it_declares():
    fields = {k: set(m.model_fields) for k, m in KINDS.items()}
    assert set(SIGN_SECTIONS) == {"doors", "duplicates", "laser", "door_camera", "belief", "navigation"}
    assert set(SIGN_SECTIONS) <= fields["doors"] and set(SIGN_SECTIONS) <= fields["chain"]
    assert not set(SIGN_SECTIONS) & fields["objects"] and not set(SIGN_SECTIONS) & fields["indirect"]
    assert {"map", "start", "robot"} <= fields["objects"] and not {"map", "start", "robot"} & fields["indirect"]


@pytest.mark.parametrize("config, section", [("office", "laser"), ("indirect_quick", "navigation"),
                                             ("indirect_quick", "robot"), ("office", "doors")])
def test_a_retired_section_is_ignored_with_a_warning_and_moves_no_fingerprint(config, section, tmp_path):
    src = TASKS["objects" if config == "office" else "indirect"]
    path = api.init(config, tmp_path / "copy")[0]  # the shipped scenario with the files it names
    d = yaml.safe_load(path.read_text())
    d[section] = {"doors": [], "laser": {"range": 6.0}, "navigation": {"replan_every": 2.0},
                  "robot": {"radius": 0.3}}[section]
    edited = path.with_name("edited.yaml")
    edited.write_text(yaml.safe_dump(d, sort_keys=False))
    with pytest.warns(DeprecationWarning, match=rf"the {section} section of a scenario of kind {src.kind} .* never used"):
        loaded = Loaded.load(edited)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plain = Loaded.load(path)
    assert plain.fingerprint == FINGERPRINTS[config]
    if section == "doors":  # the default: 0.2.0 counted the same
        assert loaded.fingerprint == plain.fingerprint


@pytest.mark.parametrize("kind, section, value", [("indirect", "map", {"image": "x.png"}), ("doors", "objects", {}),
                                                  ("objects", "chains", [])])
def test_a_section_the_kind_does_not_take_is_refused_naming_it(kind, section, value, tmp_path):
    path = TASKS[kind].example(tmp_path / "ex", "greedy" if kind == "doors" else
                               "lsos" if kind == "objects" else "UIS")
    d = yaml.safe_load(path.read_text())
    d["kind"] = kind
    d[section] = value
    path.write_text(yaml.safe_dump(d, sort_keys=False))
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    assert err.value.field == section and f"a {kind} scenario does not take {section}" in err.value.message


def test_the_command_line_shows_the_warning_on_one_line_naming_the_file(tmp_path):
    path = api.init("indirect_quick", tmp_path / "copy")[0]
    path.write_text(path.read_text() + "laser:\n  range: 6.0\n")
    res = subprocess.run([sys.executable, "-c", "from semsearch_cli.cli import main; main()", "validate", str(path)],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    line = next(ln for ln in res.stderr.splitlines() if "laser" in ln)
    assert line.startswith("DeprecationWarning: the laser section of a scenario of kind indirect (") and str(path) in line
    assert "specs.py" not in res.stderr  # semsearch's own line is not the user's business


def test_a_deprecation_never_names_a_release_after_the_one_being_made(tmp_path):
    """A warning says "deprecated since X": X is at most the release this version leads to (a
    development version 0.3.0.dev0 leads to 0.3.0), so no user reads of a version they do not have."""
    path = api.init("indirect_quick", tmp_path / "copy")[0]
    path.write_text(path.read_text() + "laser:\n  range: 6.0\n")
    with pytest.warns(DeprecationWarning) as caught:
        load_scenario(path)
    (since,) = {m.group(1) for w in caught if (m := re.search(r"deprecated since semsearch (\S+) ", str(w.message)))}
    assert Version(since) <= Version(Version(__version__).base_version)
