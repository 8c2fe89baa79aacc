"""Fingerprints that outlive new fields (issue 55): the fields of 0.3.0's kinds enter as they always
did, so the shipped scenarios keep their fingerprints; a field added since enters only when a
scenario sets it away from its default."""

import copy

import pytest
import yaml

from semsearch_cli import api, shipped
from semsearch_cli.config.fingerprint import FINGERPRINTED, drop_new_defaults, schema_fields, schema_paths
from semsearch_cli.runner import Loaded

# every shipped scenario's fingerprint on engine 2 (semsearch 0.3.0), before and after the rule
SHIPPED = {"demo": "34448576965adb4b", "hospital": "a353e5fd42377212", "hotel": "21fb09e2eca7a8ba",
           "hotel_thesis": "542be3e602930084", "indirect": "f8f7d755ac3d3019", "indirect_no_secondary": "fa98eb8c688214be",
           "indirect_quick": "98f4c46f71a669cd", "indirect_shuffled": "f9f024404e5371f5", "inverse": "e62ac938d14ba831",
           "kth": "b7f38949a00e6468", "normal": "fe245761f6ed604e", "office": "65cc8363e7d26bd9"}


def test_the_shipped_scenarios_keep_their_fingerprints():
    assert sorted(shipped.names()) == sorted(SHIPPED)
    assert {n: Loaded.load(shipped.path(n)).fingerprint for n in SHIPPED} == SHIPPED


# the fields added since 0.3.0 (outside FINGERPRINTED), each with its default: at that default a field
# does not enter the fingerprint, so its default is part of the format (changing one means adding
# the field to FINGERPRINTED, which moves every fingerprint)
ADDED_SINCE = {}


def test_the_fields_added_since_0_3_0_are_pinned_with_their_defaults():
    fields = schema_fields()
    added = set(fields) - FINGERPRINTED
    assert {p: fields[p].get_default(call_default_factory=True) for p in added} == ADDED_SINCE


def test_every_frozen_field_is_still_a_field():
    """A field leaves the scenario format only after a deprecation; the frozen list is the 0.3.0 format."""
    assert FINGERPRINTED <= schema_paths()


@pytest.mark.parametrize("name, path", [("hotel", ("navigation", "replan")), ("hotel", ("laser", "noise_std")),
                                        ("office", ("objects", "camera", "range")), ("indirect_quick", ("indirect", "noise"))])
def test_a_field_added_with_a_default_moves_no_fingerprint(name, path, tmp_path):
    """Taking a field of today out of the frozen list stands for a field added tomorrow: at its
    default it leaves the canonical form as if it did not exist; set away from it, it enters."""
    dotted = ".".join(path)
    assert dotted in FINGERPRINTED
    L = Loaded.load(shipped.path(name))
    before = copy.deepcopy(L.canonical())
    node = before
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]  # the scenario format before the field existed
    assert L.canonical(FINGERPRINTED - {dotted}) == before
    assert L.canonical(FINGERPRINTED - {dotted}) != L.canonical()  # (the field is there while it is frozen)
    # set away from its default, the new field enters
    dst = api.init(name, tmp_path / "copy")[0]
    doc = yaml.safe_load(dst.read_text())
    node = doc
    for key in path[:-1]:
        node = node.setdefault(key, {})
    node[path[-1]] = {"replan": "events", "noise_std": 0.05, "range": 2.0, "noise": {"false_positive": 0.1}}[path[-1]]
    dst.write_text(yaml.safe_dump(doc, sort_keys=False))
    edited = Loaded.load(dst)
    assert edited.canonical(FINGERPRINTED - {dotted}) != before
    node = edited.canonical(FINGERPRINTED - {dotted})
    for key in path:
        node = node[key]
    assert node is not None


def test_keys_of_a_mapping_are_data_and_new_fields_in_its_values_follow_the_rule():
    known = frozenset({"a", "a{}", "a{}.x", "b"})
    doc = {"a": {"k1": {"x": 1, "new": 0}, "k2": {"x": 2, "new": 5}}, "b": {"p": 1}, "c": None}
    away = {"a": {"k1": {}, "k2": {"new": 5}}}
    assert drop_new_defaults(doc, away, known) == {"a": {"k1": {"x": 1}, "k2": {"x": 2, "new": 5}}, "b": {"p": 1}}
    lists = frozenset({"l", "l[].x"})
    assert drop_new_defaults({"l": [{"x": 1, "y": 0}, {"x": 2, "y": 3}]}, {"l": [{}, {"y": 3}]}, lists) == \
        {"l": [{"x": 1}, {"x": 2, "y": 3}]}


def test_keys_of_a_mapping_inside_a_list_are_data_too():
    known = frozenset({"a", "a[]{}", "a[]{}.x"})
    assert drop_new_defaults({"a": [{"k": {"x": 1, "new": 0}}]}, {}, known) == {"a": [{"k": {"x": 1}}]}
