"""Write the shipped splits of semsearch-bench (semsearch_cli/data/bench/<suite>/<split>/) and
their hashes (published.json), from the suites' builders. Run from the checkout:

    python scripts/make_bench.py [SUITE ...]

A hidden split's published hash is kept as it is (null until a maintainer fills it in)."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

from semsearch_cli.bench import DATA, SUITES
from semsearch_cli.bench.suites import build, read_split


def main(names: list[str]) -> int:
    pub_file = DATA / "published.json"
    pub = json.loads(pub_file.read_text()) if pub_file.is_file() else {}
    for name in names or list(SUITES):
        suite = SUITES[name]
        entry = pub.setdefault(name, {})
        for split in suite.splits:
            entry.setdefault(split, None)
        for split in suite.shipped:
            folder = DATA / name / split
            if folder.exists():
                shutil.rmtree(folder)
            build(suite, split, f"{name}/{split}", folder)
            sp = read_split(suite, split, folder)
            entry[split] = sp.hash
            size = sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())
            print(f"{name} {split}: {len(sp.floors)} floors, {size / 1e3:.0f} kB, hash {sp.hash}")
    DATA.mkdir(parents=True, exist_ok=True)
    pub_file.write_text(json.dumps(pub, indent=1, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
