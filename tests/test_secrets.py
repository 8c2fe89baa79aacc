"""A key is written nowhere (issue 52, item 4): every output a user can ask for (runs.csv, meta.json,
summary, traces, frames, decisions, transcripts, the report, a bench folder and its board, verify)
is written with the key where it belongs, in the environment variable the llm planner reads, and
every file and file name is searched for it; each other place a user might put a key (an
address's user:password@, a query parameter, api_key_env, --planner, sweep --param, --scheduler,
--mirror, Python) is refused before anything is written, and the refusal never shows the key."""

from __future__ import annotations

import os
import uuid
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

pytest.importorskip("openai")

from semsearch_cli import api  # noqa: E402
from semsearch_cli.cli import app  # noqa: E402
from semsearch_cli.config import PlannerSpec  # noqa: E402
from semsearch_cli.credentials import redact, url_credential  # noqa: E402
from semsearch_cli.errors import PlannerError, ScenarioError  # noqa: E402
from semsearch_cli.planners import Variant  # noqa: E402
from semsearch_cli.planners.llm import LlmParams, LlmPlanner  # noqa: E402
from semsearch_cli.runner import BatchOptions  # noqa: E402

from .llm_server import ChatServer  # noqa: E402

runner = CliRunner()
KEY = f"sk-test-{uuid.uuid4().hex}"  # the key; also searched for without its prefix
BARE = KEY.removeprefix("sk-")


@pytest.fixture(autouse=True)
def own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_CACHE", str(tmp_path / "cache"))  # the request slots' lock files


def scenario(folder: Path, planners: list) -> Path:
    """The demo scenario (door search), one goal, one repeat, with these planners."""
    api.init("demo", folder / "demo", force=True)
    src = folder / "demo" / "demo.yaml"
    d = yaml.safe_load(src.read_text())
    d["planners"], d["goals"] = planners, d["goals"][:1]
    d["experiment"]["seeds"] = 1
    out = src.with_name("demo_llm.yaml")
    out.write_text(yaml.safe_dump(d))
    return out


def leaks(root: Path) -> list[str]:
    """Every file or folder under ``root`` whose name or bytes hold the key (or its tail)."""
    found = []
    for p in root.rglob("*"):
        if BARE in p.name:
            found.append(f"name: {p}")
        elif p.is_file() and not p.is_symlink() and BARE.encode() in p.read_bytes():
            found.append(f"bytes: {p}")
    return found


def invoke(args, cwd: Path):
    old = Path.cwd()
    os.chdir(cwd)
    try:
        return runner.invoke(app, [str(a) for a in args])
    finally:
        os.chdir(old)


def test_every_output_written_with_the_key_in_the_environment_holds_it_nowhere(tmp_path, monkeypatch):
    monkeypatch.setenv("SEMSEARCH_TEST_KEY", KEY)
    work = tmp_path / "work"
    work.mkdir()
    with ChatServer(models=["scripted"], key=KEY) as srv:
        llm = {"name": "llm", "base_url": srv.base_url, "model": "scripted", "api_key_env": "SEMSEARCH_TEST_KEY"}
        sc = scenario(tmp_path, [{"name": "greedy"}, llm])
        res = invoke(["run", sc, "--workers", "1", "--decisions", "--trace", "--frames", "--transcripts",
                      "--out", work / "out"], work)
        assert res.exit_code == 0, res.output
        res = invoke(["report", work / "out", "--out", work / "report"], work)
        assert res.exit_code == 0, res.output
        assert invoke(["verify", work / "out"], work).exit_code == 0
        label = f"llm[api_key_env=SEMSEARCH_TEST_KEY,base_url={srv.base_url},model=scripted]"
        res = invoke(["bench", "run", "doors-v1", "--planner", label, "--limit", "1", "--workers", "1", "--transcripts",
                      "--out", work / "bench"], work)
        assert res.exit_code == 0, res.output
        res = invoke(["bench", "board", work / "bench", "--out", work / "board"], work)
        assert res.exit_code == 0, res.output
    assert srv.keys and set(srv.keys) == {f"Bearer {KEY}"}  # the key was sent, with every call
    written = [p for p in work.rglob("*") if p.is_file()]
    names = {p.name for p in written}
    assert {"runs.csv", "meta.json", "summary.csv", "report.md", "bench.json"} <= names
    for sub in ("traces", "frames", "decisions", "transcripts"):
        assert list((work / "out" / sub).iterdir()), sub
    assert any(p.suffix == ".html" for p in (work / "board").rglob("*"))
    assert leaks(tmp_path) == []


URL_KEYS = {  # where in an address a user might write the key
    "user:password@": lambda url: url.replace("http://", f"http://apiuser:{KEY}@"),
    "key@ alone": lambda url: url.replace("http://", f"http://{KEY}@"),
    "?api_key=": lambda url: f"{url}?api_key={KEY}",
    "?key=": lambda url: f"{url}?key={KEY}",
    "?access_token=": lambda url: f"{url}?access_token={KEY}",
    "&subscription-key=": lambda url: f"{url}?api-version=2024-06-01&subscription-key={KEY}",
    "user:password@ without a scheme": lambda url: url.replace("http://", f"apiuser:{KEY}@"),
}


def refused(res, work: Path, *outs: Path) -> str:
    """The refusal's text, checked: exit 2, one paragraph, no traceback, no key, nothing written."""
    text = " ".join(res.output.split())
    assert res.exit_code == 2, text
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    assert "Traceback" not in text and BARE not in res.output
    assert list(work.iterdir()) == [], sorted(p.name for p in work.iterdir())
    assert not any(o.exists() for o in outs)
    return text


@pytest.mark.parametrize("place", sorted(URL_KEYS))
def test_a_key_in_a_scenarios_base_url_is_refused_when_it_loads(tmp_path, place):
    url = URL_KEYS[place]("http://127.0.0.1:9/v1")
    sc = scenario(tmp_path, [{"name": "greedy"}, {"name": "llm", "base_url": url, "model": "m"}])
    work = tmp_path / "work"
    work.mkdir()
    for args in (["validate", sc], ["run", sc, "--workers", "1", "--out", work / "out"],
                 ["run", sc, "--dry-run"]):
        text = refused(invoke(args, work), work, work / "out")
        assert "field 'planners[1].base_url'" in text and "api_key_env" in text and "OPENAI_API_KEY" in text
        assert "***" in text
    assert leaks(work) + leaks(tmp_path / "cache") == []  # the scenario holds the key, as its user wrote it


def test_the_refusal_reads_as_one_paragraph(tmp_path):
    sc = scenario(tmp_path, [{"name": "llm", "base_url": f"https://apiuser:{KEY}@api.example.com/v1", "model": "m"}])
    res = runner.invoke(app, ["validate", str(sc)])
    assert " ".join(res.output.split()) == (
        f"error: {sc}, field 'planners[0].base_url': 'llm[base_url=https://***@api.example.com/v1]': base_url holds a user "
        "name and password before the host (user:***@): a key is never written into an address (labels, rows, meta.json, "
        "reports and file names carry it): put the key in an environment variable and name the variable in api_key_env "
        "(default OPENAI_API_KEY; export OPENAI_API_KEY=<your key>); the address is then the host alone, e.g. "
        "https://api.example.com/v1 (docs/llm.md, Keys)")


def test_a_key_written_as_api_key_env_is_refused(tmp_path):
    sc = scenario(tmp_path, [{"name": "llm", "base_url": "http://127.0.0.1:9/v1", "model": "m", "api_key_env": KEY}])
    work = tmp_path / "work"
    work.mkdir()
    text = refused(invoke(["run", sc, "--workers", "1", "--out", work / "out"], work), work, work / "out")
    assert "field 'planners[0].api_key_env'" in text and "never the key itself" in text


@pytest.mark.parametrize("place", ["user:password@", "?api_key="])
def test_a_key_given_on_the_command_line_is_refused_before_anything_is_written(tmp_path, place):
    url = URL_KEYS[place]("http://127.0.0.1:9/v1")
    label = f"llm[base_url={url},model=m]"
    sc = scenario(tmp_path, [{"name": "greedy"}])
    work = tmp_path / "work"
    work.mkdir()
    cases = [
        (["bench", "run", "doors-v1", "--planner", label, "--limit", "1", "--out", work / "b"], "--planner"),
        (["run", sc, "--planner", label, "--out", work / "r"], "--planner"),
        (["run", sc, "--planner", f"greedy,{label}", "--out", work / "r"], "--planner"),
        (["sweep", sc, "--param", f"llm.base_url={url}", "--out", work / "s"], "--param"),
        (["run", sc, "--executor", "dask", "--scheduler", f"tcp://apiuser:{KEY}@127.0.0.1:8786", "--out", work / "r"],
         "--scheduler"),
        (["bench", "fetch", "doors-real-v1", "--mirror", URL_KEYS[place]("http://127.0.0.1:9")], "--mirror"),
    ]
    for args, flag in cases:
        text = refused(invoke(args, work), work, work / "b", work / "r", work / "s")
        assert f"field '{flag}'" in text, text
    assert leaks(work) + leaks(tmp_path / "cache") == []


def test_the_python_api_refuses_a_key_in_an_address_and_a_label_never_shows_one(tmp_path):
    sc = scenario(tmp_path, [{"name": "greedy"}])
    url = f"http://apiuser:{KEY}@127.0.0.1:9/v1"
    with pytest.raises(ScenarioError) as err:
        api.run(sc, BatchOptions(out=tmp_path / "out", workers=1), plots=False,
                planner_specs=[PlannerSpec(name="llm", base_url=url, model="m")])
    assert err.value.field == "planners[0].base_url" and BARE not in str(err.value)
    assert not (tmp_path / "out").exists()
    with pytest.raises(PlannerError) as err:  # the planner itself, built by hand
        LlmPlanner(LlmParams(base_url=url, model="m"))
    assert BARE not in str(err.value) and "api_key_env" in str(err.value)
    v = Variant("llm", (("base_url", url), ("model", "m")))
    assert BARE not in v.label and v.label == "llm[base_url=http://***@127.0.0.1:9/v1,model=m]"
    with pytest.raises(PlannerError):
        v.build()


@pytest.mark.parametrize("url, what", [
    ("http://u:p@h/v1", "a user name and password before the host (user:***@)"),
    ("http://tok@h/v1", "a user name (or key) before the host (***@)"),
    ("https://h/v1?api_key=x", "the query parameter 'api_key'"),
    ("https://h/v1?x=1;token=x", "the query parameter 'token'"),
    ("https://h/v1#access_token=x", "the query parameter 'access_token'"),
    ("https://h/v1?X-Amz-Signature=x", "the query parameter 'X-Amz-Signature'"),
    ("https://h/v1?api%5Fkey=x", "the query parameter 'api_key'"),
    ("https://h/v1?api-version=2024-06-01", None),
    ("https://h/v1?key=", None),  # no value, no key
    ("http://h/v1/a@b", None),  # an @ in the path is not userinfo
    ("prompts/a@b.txt", None),  # a path, not an address
])
def test_what_counts_as_a_credential(url, what):
    assert url_credential(url) == what
    if what:
        assert "***" in redact(url)
