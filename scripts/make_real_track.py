"""Write doors-real-v1's sources.json (semsearch_cli/data/bench/doors-real-v1/) and its published
hash, from local copies of the public sources: the authors' maps (../shared/reference_maps, as
published in mathiasmantelli/ObjectSearchROS) and a clone of the public KTH floor-plan copy
(selimon2000/GNN_Semantic_Map_Prediction). Only names, SHA-256 and URLs are written: no floor.

    python scripts/make_real_track.py --kth-repo PATH_TO_CLONE [--shared ../shared/reference_maps]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from semsearch_cli.bench import DATA, SUITES
from semsearch_cli.bench.real import build_floor, fetch, floor_hash, sha256_of, sources_file
from semsearch_cli.errors import ScenarioError

AUTHORS = "https://raw.githubusercontent.com/mathiasmantelli/ObjectSearchROS/e2de69a62d63c8aa1daa30a67b656c0818060fac"
KTH_COMMIT = "0f5ad5fd83fd9bdaf14636da661ac2611f014dbf"
KTH = f"https://raw.githubusercontent.com/selimon2000/GNN_Semantic_Map_Prediction/{KTH_COMMIT}"
# the thesis' floors: (id, stem, folder in the authors' repository, start (m), goals, segmentation delta (m^2))
THESIS = [("normal", "par_impar_par_impar", "maps", (25.5, 28.5), [54, 55, 111, 124], 4.5),
          ("inverse", "par_impar_par_impar_inverse", "maps", (25.5, 28.5), [54, 55, 111, 124], 4.5),
          ("hotel", "hotel2", "mapas", (46.0, 64.0), [76, 135, 148, 185], 2.5)]
MIN_SIGNS = 8  # a KTH floor with fewer signs is left out


def entry(path: Path, url: str) -> dict:
    return {"name": path.name, "sha256": sha256_of(path), "url": url}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kth-repo", type=Path, required=True)
    ap.add_argument("--shared", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "reference_maps")
    a = ap.parse_args()
    floors = []
    for fid, stem, folder, start, goals, delta in THESIS:
        floors.append({"id": fid, "importer": "mobilesim",
                       "options": {"resolution": 0.1, "start": list(start), "goals": goals, "density_delta": delta},
                       "files": {"map": entry(a.shared / f"{stem}.map", f"{AUTHORS}/{folder}/{stem}.map"),
                                 "doors": entry(a.shared / f"{stem}.doors", f"{AUTHORS}/{folder}/{stem}.doors")}})
    tmp = Path(tempfile.mkdtemp(prefix="semsearch-kth-"))
    names = subprocess.run(["git", "-C", str(a.kth_repo), "ls-tree", "-r", "--name-only", KTH_COMMIT], capture_output=True,
                           text=True, check=True).stdout.split()
    left = []
    for rel in sorted(n for n in names if n.endswith(".xml") and "/raw/" in n):
        f = tmp / "src" / rel  # the set has files of one name in two buildings' folders
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_bytes(subprocess.run(["git", "-C", str(a.kth_repo), "show", f"{KTH_COMMIT}:{rel}"], capture_output=True,
                                     check=True).stdout)
        # the id names the building's folder too: two buildings have files of one name
        fl = {"id": f"kth-{Path(rel).parts[1]}-{f.stem}", "importer": "kth", "options": {"resolution": 0.1, "duplicates": "any"},
              "files": {"xml": entry(f, f"{KTH}/{rel}")}}
        try:
            p = build_floor(fl, {"xml": f}, tmp / "try" / fl["id"])
        except (ScenarioError, ValueError) as exc:
            left.append(f"{fl['id']}: {getattr(exc, 'message', exc)}"[:140])
            continue
        n = sum(1 for _ in open(p.parent / "doors.csv")) - 1
        if n < MIN_SIGNS:
            left.append(f"{fl['id']}: {n} signs")
            continue
        fl["hash"] = floor_hash(p)
        floors.append(fl)
    for fl in floors[:3]:
        fl["hash"] = floor_hash(build_floor(fl, {r: a.shared / e["name"] for r, e in fl["files"].items()}, tmp / "try" / fl["id"]))
    out = sources_file("doors-real-v1")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"suite": "doors-real-v1", "floors": floors}, indent=1) + "\n")
    os.environ["SEMSEARCH_CACHE"] = str(tmp / "cache")
    split, missing = fetch(SUITES["doors-real-v1"], [a.shared, tmp / "src"])
    pub_file = DATA / "published.json"
    pub = json.loads(pub_file.read_text())
    pub["doors-real-v1"] = {"val": split.hash}
    pub_file.write_text(json.dumps(pub, indent=1, sort_keys=True) + "\n")
    print(f"doors-real-v1: {len(floors)} floors ({len(floors) - 3} KTH), hash {split.hash}; left out {len(left)}:")
    for x in left:
        print("  " + x)
    return 0


if __name__ == "__main__":
    sys.exit(main())
