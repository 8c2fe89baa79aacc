"""Hostile inputs for the language-model planner's surface and the planners' parameters (issue 52,
items 4 and 5), in the style of ``tests/hostile_release.py``: :class:`~tests.hostile_release.ReleaseCase`
cases, each a command line and what must happen.

Classes:

- ``secrets``: a key in each place a user might put one (an address's ``user:password@``, a query
  parameter, ``api_key_env``, ``--planner``, a run's ``--planner`` filter, ``sweep --param``,
  ``--scheduler``, ``bench fetch --mirror``, ``--dry-run``): refused with exit 2, naming the field,
  the key (:data:`KEY`) never in the output; the key where it belongs (an environment variable's
  name in ``api_key_env``) accepted;
- ``params``: every registered planner's parameters out of range, of the wrong type, unknown
  (the nearest valid name suggested), NaN, inf, huge, empty, given twice, true for a number, via
  ``--planner`` (bench run, a run's filter, ``sweep --param``) and via a scenario: refused naming
  the entry and the parameter (``'nsos[alpha=2]': alpha must be at most 1``) and the field;
- ``llm``: the llm planner's own inputs: addresses that are not http(s) ones, an endpoint that
  does not answer (refused at the look before the first run, exit 2, naming the planner and
  ``planners.base_url``; docs/llm.md, Before the first run), prompt files that cannot be one,
  an empty model, timeouts out of range, replay folders that hold no transcripts, a mode the kind
  does not take.

Every case that refuses does so before any connection is made, except the endpoint cases (a
closed loopback port is refused at once, fast; an address that never answers takes the 5 s
bound, ``fast=False``). No case needs a server that answers.
"""

from __future__ import annotations

import socket
from pathlib import Path

import yaml

from semsearch_cli.planners import PLANNERS

from .hostile_inputs import REPO, _dump, _set, demo_base
from .hostile_release import GOAL, ReleaseCase

CLASSES = ("secrets", "params", "llm")
KEY = "sk-hostile-0123456789abcdef0123456789abcdef"  # must never appear in a refusal's output
KEY_VARIABLE = "SEMSEARCH_HOSTILE_KEY"  # a variable's name: where a key's name belongs


def closed_port() -> int:
    """A loopback port nothing listens on (bound, then let go)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _kind_scenarios() -> dict:
    """A small scenario per kind of search, as a dict without planners: doors from the demo's
    base (set by the caller), objects from the shipped office, indirect from generated rooms."""
    office = yaml.safe_load((REPO / "semsearch_cli" / "data" / "configs" / "office.yaml").read_text())
    office["map"]["image"] = str(REPO / "semsearch_cli" / "data" / "maps" / "office" / "map.png")
    office["objects"]["cases"] = office["objects"]["cases"][:1]
    indirect = {"kind": "indirect", "name": "ind", "indirect": {"rooms": {"count": 1, "seed": 0}, "time_limit": 30},
                "experiment": {"seeds": 1}}
    return {"objects": office, "indirect": indirect}


def _bad_values(field) -> list[tuple[str, object, str]]:
    """(what, value, the words the refusal says) for one parameter of a planner's Params."""
    meta = {type(m).__name__: m for m in field.metadata}
    out = []
    ann = field.annotation
    if ann in (int, float) or str(ann).startswith(("int |", "float |")):
        if "Le" in meta:
            out.append(("above its bound", meta["Le"].le * 10 + 1, f"must be at most {meta['Le'].le:g}"))
        if "Ge" in meta:
            out.append(("below its bound", meta["Ge"].ge - 1, f"must be at least {meta['Ge'].ge:g}"))
        elif "Gt" in meta:
            out.append(("at its open bound", meta["Gt"].gt, f"must be more than {meta['Gt'].gt:g}"))
        out.append(("text", "lots", "must be a"))
    return out


def build_cases(root: Path) -> list[ReleaseCase]:
    """Every case of the catalogue, its files written under ``root`` (no run is made to build it)."""
    root.mkdir(parents=True, exist_ok=True)
    base, _ = demo_base(root)
    base = _set(base, ["goals"], [GOAL])
    good = _dump(root / "good.yaml", base)
    kinds = _kind_scenarios()
    cases: list[ReleaseCase] = []
    out = root / "out"
    closed = f"http://127.0.0.1:{closed_port()}/v1"

    def out_dir() -> Path:
        return out / f"case{len(cases)}"

    def add(category, name, args, expect="refuse", says=(), fast=True, within=None):
        assert category in CLASSES, category
        cases.append(ReleaseCase(category, name, [str(a) for a in args], expect, False, tuple(says), fast=fast, within=within))

    def scen(category: str, name: str, data, file: str = "scenario.yaml") -> Path:
        d = root / category / "".join(c if c.isalnum() or c in "._-" else "_" for c in name)[:60]
        d.mkdir(parents=True, exist_ok=True)
        return _dump(d / file, data)

    def with_llm(**params) -> dict:
        return _set(base, ["planners"], [{"name": "greedy"}, {"name": "llm", "model": "m", "base_url": closed, **params}])

    run = ["--seeds", "1", "--workers", "1"]

    # -- secrets: a key in each place a user might put one ---------------------------------------
    urls = {
        "user:password@": f"http://apiuser:{KEY}@127.0.0.1:9/v1",
        "key@ alone": f"http://{KEY}@127.0.0.1:9/v1",
        "?api_key=": f"http://127.0.0.1:9/v1?api_key={KEY}",
        "?key=": f"http://127.0.0.1:9/v1?key={KEY}",
        "?token=": f"http://127.0.0.1:9/v1?token={KEY}",
        "?access_token=": f"https://api.example.com/v1?access_token={KEY}",
        "&subscription-key= after api-version": f"https://api.example.com/v1?api-version=2024-06-01&subscription-key={KEY}",
        "#token= in the fragment": f"https://api.example.com/v1#token={KEY}",
        "user:password@ without a scheme": f"apiuser:{KEY}@localhost:8000/v1",
    }
    for where, url in urls.items():
        add("secrets", f"scenario base_url with {where}", ["validate", scen("secrets", where, with_llm(base_url=url))],
            says=["planners[1].base_url", "api_key_env", "***"])
    p = scen("secrets", "run_userinfo", with_llm(base_url=urls["user:password@"]))
    add("secrets", "run of a scenario whose base_url has user:password@", ["run", p, *run, "--out", out_dir()],
        says=["planners[1].base_url", "***"])
    add("secrets", "run --dry-run of a scenario whose base_url has ?api_key=",
        ["run", scen("secrets", "dry_query", with_llm(base_url=urls["?api_key="])), "--dry-run"],
        says=["planners[1].base_url", "***"])
    add("secrets", "api_key_env holding the key itself", ["validate", scen("secrets", "env_is_key", with_llm(api_key_env=KEY))],
        says=["planners[1].api_key_env", "never the key itself"])
    add("secrets", "api_key_env holding text that is no variable's name",
        ["validate", scen("secrets", "env_not_name", with_llm(api_key_env="my key=abc"))], says=["planners[1].api_key_env"])
    for where in ("user:password@", "?api_key="):
        label = f"llm[base_url={urls[where]},model=m]"
        add("secrets", f"bench run --planner with {where}", ["bench", "run", "doors-v1", "--planner", label, "--limit", "1",
                                                             "--out", out_dir()], says=["--planner", "***"])
        add("secrets", f"run's --planner filter with {where}", ["run", good, *run, "--planner", label, "--out", out_dir()],
            says=["--planner", "***"])
    llm_ok = scen("secrets", "llm_ok", with_llm())
    add("secrets", "sweep --param llm.base_url with user:password@",
        ["sweep", llm_ok, *run, "--param", f"llm.base_url={urls['user:password@']}", "--out", out_dir()], says=["--param", "***"])
    add("secrets", "--scheduler with user:password@",
        ["run", good, "--seeds", "1", "--executor", "dask", "--scheduler", f"tcp://apiuser:{KEY}@127.0.0.1:8786", "--out",
         out_dir()], says=["--scheduler", "***"])
    add("secrets", "bench fetch --mirror with user:password@", ["bench", "fetch", "doors-real-v1", "--mirror",
                                                                f"http://apiuser:{KEY}@127.0.0.1:9/"], says=["--mirror", "***"])
    add("secrets", "api_key_env naming a variable (the key's place)",
        ["validate", scen("secrets", "env_named", with_llm(api_key_env=KEY_VARIABLE))], "accept")
    add("secrets", "base_url with ?api-version= (no credential)",
        ["validate", scen("secrets", "api_version", with_llm(base_url=closed + "?api-version=2024-06-01"))], "accept")
    add("secrets", "run --dry-run with api_key_env naming a variable (calls nothing)",
        ["run", scen("secrets", "dry_env", with_llm(api_key_env=KEY_VARIABLE)), "--dry-run"], "accept")

    # -- params: every registered planner's parameters --------------------------------------------
    for name, cls in sorted(PLANNERS.items()):
        if not cls.__module__.startswith("semsearch_cli."):
            continue
        fields = cls.Params.model_fields
        kind = cls.task
        doc = base if kind == "doors" else kinds.get(kind)
        if not fields:
            add("params", f"{name}: a parameter it does not take, via --planner",
                ["run", good, *run, "--planner", f"{name}[alpha=1]", "--out", out_dir()],
                says=["--planner", f"'{name}[alpha=1]'", f"{name!r} has no parameter 'alpha'"])
            continue
        done = False
        for k, f in fields.items():
            bad = _bad_values(f)
            if not bad or done:
                continue
            done = True
            what, value, words = bad[0]
            add("params", f"{name}.{k} {what} via --planner", ["run", good, *run, "--planner", f"{name}[{k}={value}]",
                                                                 "--out", out_dir()],
                says=["--planner", f"'{name}[{k}={value}]'", f"{k} {words}"])
            if doc is not None and name != "llm":
                what, value, words = bad[-1]
                add("params", f"{name}.{k} {what} in a scenario",
                    ["validate", scen("params", f"{name}_{k}", _set(doc, ["planners"], [{"name": name, k: value}]))],
                    says=["planners[0]." + k, f"{k} {words}"])
    nsos = [("alpah=0.5", ["'nsos[alpah=0.5]'", "did you mean 'alpha'"]),
            ("alpha=.nan", ["'nsos[alpha=nan]'", "alpha must be a finite number"]),
            ("alpha=nan", ["'nsos[alpha=nan]'", "alpha must be a finite number"]),
            ("w_g=inf", ["'nsos[w_g=inf]'", "w_g must be a finite number"]),
            ("w_g=1e999", ["w_g must be a finite number"]),
            ("door_bins=1000000000000", ["door_bins must be at most 3600"]),
            ("door_bins=2.5", ["door_bins must be a whole number"]),
            ("door_bins=true", ["door_bins must be a number, not true or false"]),
            ("alpha=", ["alpha has no value"]),
            ("alpha=0.5,alpha=0.6", ["alpha is given twice"]),
            ("alpha=[0.5", ["give NAME or NAME[key=value,...]"])]
    for text, says in nsos:
        add("params", f"bench run --planner nsos[{text}]", ["bench", "run", "doors-v1", "--planner", f"nsos[{text}]", "--limit",
                                                             "1", "--out", out_dir()], says=["--planner", *says])
    add("params", "numbering[sigma=0] via bench run", ["bench", "run", "doors-v1", "--planner", "numbering[sigma=0]", "--limit", "1",
                                                        "--out", out_dir()], says=["--planner", "'numbering[sigma=0]': sigma must be more than 0"])
    add("params", "sweep --param nsos.alpha=0.5,2 (one value out of range)",
        ["sweep", scen("params", "sweep_nsos", _set(base, ["planners"], [{"name": "nsos"}])), *run, "--param", "nsos.alpha=0.5,2",
         "--out", out_dir()], says=["--param", "'nsos[alpha=2]': alpha must be at most 1"])
    add("params", "sweep --param nsos.alpah=2 (unknown)",
        ["sweep", scen("params", "sweep_nsos", _set(base, ["planners"], [{"name": "nsos"}])), *run, "--param", "nsos.alpah=2",
         "--out", out_dir()], says=["--param", "did you mean 'alpha'"])
    for name, value, says in (("alpha: .nan", float("nan"), "alpha must be a finite number"),
                              ("alpha: .inf", float("inf"), "alpha must be a finite number"),
                              ("alpha: null", None, "alpha must be a number (it is empty)"),
                              ("alpha: []", [], "alpha is an empty list"),
                              ("alpha: [0.5, 2] (a sweep, one out of range)", [0.5, 2], "'nsos[alpha=2]': alpha must be at most 1"),
                              ("w_g: 1e308 (huge, finite)", 1e308, None)):
        doc = _set(base, ["planners"], [{"name": "nsos", "alpha" if name.startswith("alpha") else "w_g": value}])
        add("params", f"scenario nsos {name}", ["validate", scen("params", f"nsos_{name}", doc)],
            "refuse" if says else "accept", says=["planners[0]", says] if says else ())
    add("params", "scenario ISCG-PN-HM visited: far (not a choice)",
        ["validate", scen("params", "iscg_visited", _set(kinds["indirect"], ["planners"], [{"name": "ISCG-PN-HM", "visited": "far"}]))],
        says=["planners[0].visited", "visited must be one of 'seen' or 'near'"])
    add("params", "scenario lsos window: true (a bool for a number)",
        ["validate", scen("params", "lsos_bool", _set(kinds["objects"], ["planners"], [{"name": "lsos", "window": True}]))],
        says=["planners[0].window", "must be a number, not true or false"])
    add("params", "run --planner nsos[alpha=0.5,w_g=4] (a label with two parameters, one value)",
        ["run", scen("params", "two_params", _set(base, ["planners"], [{"name": "nsos", "alpha": 0.5, "w_g": 4}])), *run,
         "--planner", "nsos[alpha=0.5,w_g=4]", "--out", out_dir()], "accept")

    # -- llm: the language-model planner's own inputs --------------------------------------------
    for url in ("ftp://127.0.0.1/v1", "localhost:8000", "http://", "file:///etc/passwd", "javascript:alert(1)", "",
                "http://[::1", "http://127.0.0.1:99999/v1"):
        add("llm", f"base_url {url!r}", ["validate", scen("llm", f"url_{url}", with_llm(base_url=url))],
            says=["planners[1].base_url"])
    add("llm", "a closed port: refused at the look before the first run", ["run", scen("llm", "closed", with_llm()), *run,
                                                                            "--out", out_dir()],
        says=["planners.base_url", "llm[", "no connection"], within=10)
    add("llm", "a closed port via bench run --planner", ["bench", "run", "doors-v1", "--planner", f"llm[base_url={closed},model=m]",
                                                         "--limit", "1", "--out", out_dir()], says=["--planner", "no connection"])
    add("llm", "an address that never answers: refused after the 5 s look",
        ["run", scen("llm", "blackhole", with_llm(base_url="http://10.255.255.1:8000/v1")), *run, "--out", out_dir()],
        says=["planners.base_url", "llm["], fast=False, within=20)
    for name, model in (("empty", ""), ("blank", "   ")):
        add("llm", f"model {name}", ["validate", scen("llm", f"model_{name}", with_llm(model=model))], says=["planners[1].model"])
    for value, says in ((0, "must be more than 0"), (-1, "must be more than 0"), (1e9, "must be at most 3600"),
                        ("soon", "must be a number"), (float("nan"), "must be a finite number")):
        add("llm", f"timeout_s {value!r}", ["validate", scen("llm", f"timeout_{value}", with_llm(timeout_s=value))],
            says=["planners[1].timeout_s", says])
    for k, v, says in (("temperature", 3, "must be at most 2"), ("max_concurrent", 0, "must be at least 1"),
                       ("retries", 11, "must be at most 10"), ("mode", "oracle", "must be one of")):
        add("llm", f"{k} {v!r}", ["validate", scen("llm", f"{k}_{v}", with_llm(**{k: v}))], says=[f"planners[1].{k}", says])
    d = root / "llm" / "prompts"
    d.mkdir(parents=True, exist_ok=True)
    (d / "nosections.txt").write_text("Find the door.\n")
    (d / "badfield.txt").write_text("=== system ===\nYou search.\n=== user ===\n$observation $password\n")
    (d / "dollar.txt").write_text("=== system ===\nCosts $5.\n=== user ===\n$observation\n")
    (d / "binary.txt").write_bytes(b"\xff\xfe\x00=== system ===\n")
    (d / "folder.txt").mkdir(exist_ok=True)
    for file, says in (("missing.txt", ["planners[1].prompt", "does not exist"]), ("nosections.txt", ["prompt", "=== system ==="]),
                       ("badfield.txt", ["prompt", "$password"]), ("dollar.txt", ["prompt", "$$"]),
                       ("binary.txt", ["prompt", "cannot read"]), ("folder.txt", ["prompt"])):
        add("llm", f"prompt file {file}", ["validate", scen("llm", f"prompt_{file}", with_llm(prompt=str(d / file)))], says=says)
    empty = root / "llm" / "empty_replay"
    empty.mkdir(parents=True, exist_ok=True)
    add("llm", "replay of a folder that does not exist", ["validate", scen("llm", "replay_missing", with_llm(replay=str(root / "nowhere")))],
        says=["planners[1].replay", "does not exist"])
    add("llm", "replay of a file, not a folder", ["validate", scen("llm", "replay_file", with_llm(replay=str(good)))],
        says=["planners[1].replay"])
    add("llm", "replay of an empty folder", ["run", scen("llm", "replay_empty", _set(base, ["planners"], [
        {"name": "llm", "replay": str(empty)}])), *run, "--out", out_dir()], says=["replay"])
    add("llm", "mode estimator in indirect search",
        ["validate", scen("llm", "indirect_estimator", _set(kinds["indirect"], ["planners"], [
            {"name": "llm", "model": "m", "base_url": closed, "mode": "estimator"}]))], says=["planners[0].mode", "indirect"])
    add("llm", "run --transcripts where transcripts/ is a file",
        ["run", scen("llm", "transcripts_file", with_llm()), *run, "--transcripts", "--out", _file_in(out_dir(), "transcripts")],
        says=["transcripts"])
    add("llm", "a scenario of llm with every parameter valid", ["validate", scen("llm", "valid", with_llm(timeout_s=5, retries=0))],
        "accept")
    return cases


def _file_in(folder: Path, name: str) -> Path:
    """``folder``, made, with a file where ``name`` (a folder a run writes) would go."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text("x")
    return folder
