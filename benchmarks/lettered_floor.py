"""nsos against greedy on our Hotel floor with its signs relabelled as real buildings write them.

    python benchmarks/lettered_floor.py [--starts 10] [--workers 2] [--out DIR] [--md FILE]

The Hotel's 124 signs (configs/hotel.yaml) are read under three labellings, on one frozen episode
set (the drawn starts of configs/hotel.yaml, their goals relabelled), so that every difference is
paired on the same start:

- ``plain``: the numbers as shipped (148);
- ``wing``: every sign prefixed by its wing, ``K148``: one prefix for all, so nsos must travel
  exactly as on plain numbers. A run's random stream is seeded by its episode's content, goal
  label included, so the batches draw other streams (nsos breaks exact ties from it); the script
  therefore also re-runs every wing episode on the plain episode's stream and checks, run for
  run, that the distances are identical;
- ``pairs``: two neighbouring numbers share one number and a suffix, as rooms 24A and 24B do
  (148 -> 148A, 149 -> 148B): nsos reasons on the number, so it sees half as many distinct numbers.

For each labelling it prints nsos[alpha=0.9] minus greedy, paired per episode (mean distance in
metres with a 95% bootstrap interval over episodes, Wilcoxon p; report/stats.paired), and success.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from semsearch_cli.api import episodes as write_episodes  # noqa: E402
from semsearch_cli.report.document import markdown_table  # noqa: E402
from semsearch_cli.report.stats import paired  # noqa: E402
from semsearch_cli.runner import BatchOptions, expand, Loaded, run_batch  # noqa: E402
from semsearch_cli.tasks.episodes import Episode  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCHEMES = {
    "plain": lambda n: str(n),
    "wing": lambda n: f"K{n}",
    "pairs": lambda n: f"{n - n % 2}{'AB'[n % 2]}",
}
PLANNERS = [{"name": "greedy"}, {"name": "nsos", "alpha": 0.9}]


@dataclass(frozen=True)
class OnStream(Episode):
    """An episode searched for its own goal on the random stream of another's content."""

    stream: str = ""

    @property
    def content(self) -> str:
        return self.stream


def same_stream_check(work: Path, starts: int, episodes: pd.DataFrame) -> tuple[int, int]:
    """(runs, runs with identical distance): every planner on every wing episode, on the stream of
    the plain episode it relabels, against the plain run."""
    plain = Loaded.load(work / "hotel_plain.yaml").task
    wing = Loaded.load(work / "hotel_wing.yaml").task
    same = n = 0
    for variant in plain.variants():
        for ep_p, ep_w in zip(plain.episodes, wing.episodes):
            a = plain.run(variant, ep_p, 0)
            b = wing.run(variant, OnStream(ep_w.index, ep_w.goal, ep_w.x, ep_w.y, ep_w.heading, ep_w.room,
                                           ep_w.shortest_m, stream=ep_p.content), 0)
            n += 1
            same += a.distance_m == b.distance_m and a.outcome == b.outcome
    return n, same


def scenario(work: Path, scheme: str, episodes: pd.DataFrame, starts: int) -> Path:
    rename = SCHEMES[scheme]
    doors = pd.read_csv(ROOT / "maps/hotel/doors.csv")
    doors["number"] = [rename(int(n)) for n in doors["number"]]
    doors.to_csv(work / f"doors_{scheme}.csv", index=False)
    eps = episodes.copy()
    eps["goal"] = [rename(int(g)) for g in eps["goal"]]
    eps = eps.groupby("goal", sort=False).head(starts)
    eps.to_csv(work / f"episodes_{scheme}.csv", index=False)
    d = yaml.safe_load((ROOT / "configs/hotel.yaml").read_text())
    d.update(name=f"hotel_{scheme}", doors=str(work / f"doors_{scheme}.csv"), planners=PLANNERS,
             goals=list(dict.fromkeys(eps["goal"])), episodes={"file": str(work / f"episodes_{scheme}.csv")})
    d["map"]["image"] = str(ROOT / "maps/hotel/map.png")
    p = work / f"hotel_{scheme}.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False))
    return p


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", type=int, default=10, help="drawn starts per goal (at most hotel.yaml's 10)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="folder for the runs (a temporary one by default)")
    ap.add_argument("--md", type=Path, default=None, help="also write the table as Markdown")
    a = ap.parse_args()
    work = a.out or Path(tempfile.mkdtemp(prefix="lettered_"))
    work.mkdir(parents=True, exist_ok=True)
    write_episodes(ROOT / "configs/hotel.yaml", work / "episodes.csv")
    episodes = pd.read_csv(work / "episodes.csv")
    rows, runs = [], {}
    for scheme in SCHEMES:
        t0 = time.perf_counter()
        loaded = Loaded.load(scenario(work, scheme, episodes, a.starts))
        df = run_batch(loaded, expand(loaded), work / scheme, BatchOptions(workers=a.workers))
        runs[scheme] = df
        g, n = df[df["planner"] == "greedy"], df[df["planner"].str.startswith("nsos")]
        pr = paired(n, g)
        rows.append({"labels": scheme, "example": SCHEMES[scheme](148), "episodes": pr["n_pairs"],
                     "nsos found": f"{(n['outcome'] == 'found').mean():.0%}", "greedy found": f"{(g['outcome'] == 'found').mean():.0%}",
                     "nsos mean (m)": round(n["distance_m"].mean(), 1), "greedy mean (m)": round(g["distance_m"].mean(), 1),
                     "nsos - greedy (m)": f"{pr['mean_diff']:+.1f} [{pr['diff_lo']:+.1f}, {pr['diff_hi']:+.1f}]",
                     "p": round(pr["p_value"], 3), "seconds": round(time.perf_counter() - t0, 1)})
    table = markdown_table(pd.DataFrame(rows))
    print(table)
    key = ["planner", "episode", "seed"]
    plain = runs["plain"].set_index(key)["distance_m"].sort_index()
    wing = runs["wing"].set_index(key)["distance_m"].sort_index()
    print(f"\nwing (K148) against plain (148) as batches (each on its own streams): "
          f"{int((plain.to_numpy() == wing.to_numpy()).sum())} of {len(plain)} runs travel the same distance")
    n, same = same_stream_check(work, a.starts, episodes)
    print(f"wing against plain on the plain episodes' streams: {same} of {n} runs identical (distance and outcome)")
    if a.md:
        a.md.write_text(table + "\n")
    return 0 if same == n else 1


if __name__ == "__main__":
    sys.exit(main())
