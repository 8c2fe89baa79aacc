"""Fuzz: scenarios drawn from the scenario model's own JSON schema and mutated (values of the
field's type in and out of range, NaN and infinity, wrong types, deleted and unknown keys, junk
sections, broken files). Whatever the input, `semsearch validate` accepts it (exit 0) or
refuses it (exit 2 with one paragraph); it never raises.

CI runs a fixed, bounded set of examples (profile ``ci``); a longer random search runs with
``SEMSEARCH_FUZZ=nightly python -m pytest tests/test_fuzz.py`` (docs/usage.md, "Bad input").
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from semsearch_cli.cli import app
from semsearch_cli.config import scenario_schema

from .hostile_inputs import demo_base

settings.register_profile("ci", max_examples=60, derandomize=True, deadline=None, database=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
settings.register_profile("nightly", max_examples=2000, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
FUZZ = settings(settings.get_profile(os.environ.get("SEMSEARCH_FUZZ", "ci")))

SCHEMA = scenario_schema()
runner = CliRunner()
_TMP = tempfile.TemporaryDirectory(prefix="semsearch-fuzz-")
ROOT = Path(_TMP.name)
BASE, DEMO = demo_base(ROOT)
# object search on the demo map (small, so that an example validates in a fraction of a second)
OBJECTS = {k: v for k, v in BASE.items() if k not in ("doors", "goals", "planners")} | {
    "planners": [{"name": "lsos"}],
    "objects": {"places": [{"name": "A", "x": 8.0, "y": 15.0}, {"name": "B", "x": 22.0, "y": 5.0}, {"name": "C", "x": 15.0, "y": 10.0}],
                "fixed": {"C": "book"}, "recording_hours": [3, 11, 19],
                "timelines": {"Day": {"mug": {3: "A", 11: "B"}}}, "requests": [{"class": "mug", "hour": 12}]}}
INDIRECT = {"name": "fuzz-indirect", "indirect": {"rooms": {"count": 2, "seed": 0}, "time_limit": 30, "view_scales": [1.0]},
            "planners": [{"name": "UIS"}], "experiment": {"seeds": 1}}


def _deref(node: dict) -> dict:
    while "$ref" in node:
        node = SCHEMA["$defs"][node["$ref"].rsplit("/", 1)[1]]
    return node


def _paths(node: dict, path: tuple = (), depth: int = 0) -> list[tuple[tuple, dict]]:
    """Every field path of the schema (list items as index 0), with the field's schema."""
    node = _deref(node)
    out = [(path, node)] if path else []
    if depth > 6:
        return out
    for branch in node.get("anyOf", []):
        out += [p for p in _paths(branch, path, depth + 1) if p[0] != path]
    for key, sub in node.get("properties", {}).items():
        out += _paths(sub, path + (key,), depth + 1)
    if "items" in node:
        out += _paths(node["items"], path + (0,), depth + 1)
    return out


PATHS = sorted({p: s for p, s in _paths(SCHEMA)}.items(), key=lambda ps: str(ps[0]))

JUNK = st.one_of(st.none(), st.booleans(), st.integers(min_value=-(2**70), max_value=2**70),
                 st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
                 st.sampled_from(["", "..", "/dev/zero", "/dev/null", "[/x]", "[bold]", ".inf", "random", "\x00"]),
                 st.lists(st.integers(), max_size=3), st.dictionaries(st.text(max_size=4), st.integers(), max_size=2))


def _typed(node: dict) -> st.SearchStrategy:
    """Values of the field's own type, in range and just out of it."""
    node = _deref(node)
    if "anyOf" in node:
        return st.one_of([_typed(b) for b in node["anyOf"]])
    if "const" in node:
        return st.just(node["const"])
    if "enum" in node:
        return st.sampled_from(node["enum"])
    kind = node.get("type")
    lo = node.get("minimum", node.get("exclusiveMinimum"))
    hi = node.get("maximum", node.get("exclusiveMaximum"))
    edges = [v for b in (lo, hi) if b is not None for v in (b, b - 1e-9, b + 1e-9, b * 10 + 1)]
    if kind == "number":
        inside = st.floats(lo if lo is not None else -1e6, hi if hi is not None else 1e6, allow_nan=False)
        return st.one_of(inside, st.sampled_from(edges or [0.0, -1.0, 1e9]), st.floats(allow_nan=True, allow_infinity=True))
    if kind == "integer":
        inside = st.integers(int(lo) if lo is not None else -1000, int(hi) if hi is not None else 1000)
        return st.one_of(inside, st.sampled_from([int(e) for e in edges] or [0, -1, 10**9]))
    if kind == "string":
        return st.one_of(st.text(max_size=12), st.sampled_from(["map.png", "doors.csv", "nope.yaml", "/dev/zero", ".."]))
    if kind == "boolean":
        return st.booleans()
    if kind == "array":
        return st.lists(_typed(node.get("items", {})), max_size=3)
    if kind == "object":
        return st.dictionaries(st.sampled_from(sorted(node.get("properties", {})) or ["x"]), JUNK, max_size=3)
    return JUNK


def _set(doc, path: tuple, value, delete: bool = False):
    """``doc`` with ``path`` set (or deleted), creating sections on the way; a path through a value
    of another shape replaces that value."""
    doc = yaml.safe_load(yaml.safe_dump(doc))
    cur = doc
    for k in path[:-1]:
        if isinstance(k, int):
            if not isinstance(cur, list) or not cur:
                return doc
            cur = cur[0]
        else:
            if not isinstance(cur, dict):
                return doc
            if not isinstance(cur.get(k), (dict, list)):
                cur[k] = {}
            cur = cur[k]
    last = path[-1]
    if isinstance(last, int):
        if isinstance(cur, list) and cur:
            if delete:
                cur.pop(0)
            else:
                cur[0] = value
    elif isinstance(cur, dict):
        if delete:
            cur.pop(last, None)
        else:
            cur[last] = value
    return doc


@st.composite
def mutated(draw) -> dict:
    doc = draw(st.sampled_from([BASE, OBJECTS, INDIRECT]))
    for _ in range(draw(st.integers(1, 3))):
        path, node = draw(st.sampled_from(PATHS))
        op = draw(st.sampled_from(["typed", "typed", "junk", "delete", "unknown"]))
        if op == "typed":
            doc = _set(doc, path, draw(_typed(node)))
        elif op == "junk":
            doc = _set(doc, path, draw(JUNK))
        elif op == "delete":
            doc = _set(doc, path, None, delete=True)
        else:
            doc = _set(doc, path[:-1] + (draw(st.text(min_size=1, max_size=8)),), draw(JUNK)) if len(path) > 1 else doc
    return doc


def _validate(path: Path) -> None:
    res = runner.invoke(app, ["validate", str(path)])
    assert res.exception is None or isinstance(res.exception, SystemExit), f"{type(res.exception).__name__}: {res.exception}"
    assert res.exit_code in (0, 2), res.output
    event("accepted" if res.exit_code == 0 else "refused")  # --hypothesis-show-statistics counts them
    if res.exit_code == 2:
        assert "error:" in res.output and "Traceback" not in res.output, res.output


def _write(doc, name: str = "fuzz.yaml") -> Path:
    p = ROOT / name
    p.write_text(yaml.safe_dump(doc, allow_unicode=True))
    return p


def test_the_schema_reaches_every_section():
    tops = {p[0] for p, _ in PATHS}
    assert {"map", "start", "robot", "laser", "door_camera", "belief", "experiment", "objects", "indirect", "chains"} <= tops
    assert ("objects", "camera", "p_detect") in {p for p, _ in PATHS}


@FUZZ
@given(mutated())
def test_validate_accepts_or_refuses_a_mutated_scenario(doc):
    _validate(_write(doc))


@FUZZ
@given(st.sampled_from(["doors", "map"]), st.binary(max_size=300), st.sampled_from([".csv", ".yaml", ".png"]))
def test_validate_refuses_a_broken_file_cleanly(which, data, suffix):
    f = ROOT / f"broken{suffix}"
    f.write_bytes(data)
    doc = _set(BASE, ("doors",), str(f)) if which == "doors" else _set(BASE, ("map", "image"), str(f))
    _validate(_write(doc))


@FUZZ
@given(st.text(max_size=400))
def test_validate_reads_any_text_as_a_scenario_or_refuses_it(text):
    p = ROOT / "text.yaml"
    p.write_text(text, encoding="utf-8", errors="surrogatepass") if not any(0xD800 <= ord(c) <= 0xDFFF for c in text) else p.write_bytes(b"\xed\xa0\x80")
    _validate(p)

