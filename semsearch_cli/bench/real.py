"""Real floors that may not be shipped: a track named by its sources, fetched on the user's machine.

``doors-real-v1`` is the authors' own simulation maps (the thesis' Normal, Inverse and Hotel, from
their public repository) and the floors of the public KTH campus floor-plan set that import with
enough signs. semsearch ships only ``sources.json``: for each floor, its importer and options and
each file it is made from, by name, SHA-256 and public URL (pinned to a commit). ``semsearch
bench fetch doors-real-v1`` gets each file (from the cache, from ``--from DIR`` when a copy lies
there, else from its URL, or from ``--mirror URL`` standing for the URL's host), checks its
SHA-256, imports the floor as ``semsearch import`` does, draws its episodes as doors-v1's (four
goals, five starts each) and checks the floor's content hash against the one ``sources.json``
records. The split is built in the cache; it is official when every floor is there (its hash is
then the published one). ``--partial`` builds it from the floors whose files were found (not
official, every floor still checked).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

import yaml

from ..errors import ScenarioError
from ..files import cache_dir, sha256_file
from ..world.importers.kth import import_kth
from ..world.importers.mobilesim import import_mobilesim
from .make import DEFAULT_PLANNER, DOORS_V1_MIN_DISTANCE, DOORS_V1_STARTS, floor_rng, freeze_episodes
from .suites import DATA, Split, Suite, fetched_folder, read_split, scenario_content, write_manifest

TIMEOUT_S = 60.0  # per file fetched


def sources_file(suite: str) -> Path:
    return DATA / suite / "sources.json"


def read_sources(suite: str) -> dict:
    f = sources_file(suite)
    try:
        return json.loads(f.read_text())
    except (OSError, ValueError) as exc:
        raise ScenarioError(str(f), "", f"cannot read the track's sources ({exc})") from None


def sha256_of(path: Path) -> str:
    """A file's SHA-256 (:func:`~semsearch_cli.files.sha256_file`)."""
    return sha256_file(path)


def _find_local(name: str, sha: str, roots: list[Path]) -> Path | None:
    for root in roots:
        for p in sorted(Path(root).rglob(name)):
            if p.is_file() and sha256_of(p) == sha:
                return p
    return None


def acquire(entry: dict, from_dirs: list[Path], mirror: str | None) -> Path | str:
    """The cached copy of a source file (fetched into the cache when needed), or why it could
    not be had (text)."""
    name, sha = entry["name"], entry["sha256"]
    dest = cache_dir() / "sources" / sha[:2] / f"{sha}-{name}"
    if dest.is_file() and sha256_of(dest) == sha:
        return dest
    dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = dest.with_name(f"{dest.name}.{os.getpid()}.tmp")
    local = _find_local(name, sha, from_dirs)
    if local is not None:
        shutil.copyfile(local, tmp)
    else:
        url = entry["url"]
        if mirror:
            url = mirror.rstrip("/") + urllib.parse.urlparse(url).path
        try:
            with urllib.request.urlopen(url, timeout=TIMEOUT_S) as resp, open(tmp, "wb") as fh:
                shutil.copyfileobj(resp, fh)
        except (urllib.error.URLError, OSError, ValueError) as exc:
            tmp.unlink(missing_ok=True)
            return f"{name}: not found{' under ' + ', '.join(map(str, from_dirs)) if from_dirs else ''}, and {url} " \
                   f"could not be fetched ({getattr(exc, 'reason', exc)})"
    got = sha256_of(tmp)
    if got != sha:
        tmp.unlink(missing_ok=True)
        return f"{name}: its SHA-256 is {got[:16]}, the track names {sha[:16]} (another version of the file)"
    os.replace(tmp, dest)
    return dest


def build_floor(floor: dict, files: dict[str, Path], out: Path) -> Path:
    """Import one floor from its fetched files into ``out`` and freeze its episodes; returns its
    scenario."""
    o = floor.get("options", {})
    name = f"doors-real-v1-{floor['id']}"
    if floor["importer"] == "mobilesim":
        path, _ = import_mobilesim(files["map"], files["doors"], out, o.get("resolution", 0.1), tuple(o["start"]),
                                   o.get("goals"), o.get("density_delta", 2.5), name, o.get("duplicates", "error"))
    elif floor["importer"] == "kth":
        path, _ = import_kth(files["xml"], out, o.get("resolution", 0.1), o.get("goals"), name,
                             duplicates=o.get("duplicates", "any"))
    else:
        raise ScenarioError(str(sources_file("doors-real-v1")), "importer", f"unknown importer {floor['importer']!r}")
    doc = yaml.safe_load(path.read_text())
    rng = floor_rng("public", "doors-real-v1", "val", int(hashlib.sha256(floor["id"].encode()).hexdigest()[:8], 16))
    doc["episodes"] = {"starts": DOORS_V1_STARTS, "seed": int(rng.integers(2**31)), "min_distance": DOORS_V1_MIN_DISTANCE}
    doc["planners"] = DEFAULT_PLANNER
    path.write_text(path.read_text().split("\n", 1)[0] + "\n" + yaml.safe_dump(doc, sort_keys=False))
    freeze_episodes(path, 1, rng)  # an unsolvable start drawn again by the floor's generator
    return path


def floor_hash(scenario: Path) -> str:
    return hashlib.sha256(json.dumps(scenario_content(scenario), sort_keys=True).encode()).hexdigest()


def _built(suite: Suite, fl: dict, files: dict, tmp: Path) -> tuple[str, dict]:
    """Import one floor into ``tmp`` and check it against the content hash the track records."""
    path = build_floor(fl, files, tmp / fl["id"])
    h = floor_hash(path)
    if fl.get("hash") and h != fl["hash"]:
        raise ScenarioError(str(sources_file(suite.name)), f"floors[{fl['id']}].hash",
                            f"the floor imports to content {h[:16]}, the track records {fl['hash'][:16]}: this "
                            "semsearch's importer differs from the one the track was made with")
    return fl["id"], {"importer": fl["importer"], "sources": {r: e["sha256"] for r, e in fl["files"].items()}, "hash": h}


def fetch(suite: Suite, from_dirs=(), mirror: str | None = None, partial: bool = False, progress=None) -> tuple[Split, list[str]]:
    """Fetch a track's sources and build its split in the cache (see the module docstring).
    Returns the split and the floors left out (with why)."""
    src = read_sources(suite.name)
    floors = src["floors"]
    got, missing = {}, []
    for k, fl in enumerate(floors):
        files, why = {}, []
        for role, entry in fl["files"].items():
            r = acquire(entry, [Path(d) for d in from_dirs], mirror)
            if isinstance(r, Path):
                files[role] = r
            else:
                why.append(r)
        if why:
            missing.append(f"{fl['id']}: {why[0]}")
        else:
            got[fl["id"]] = files
        if progress:
            progress(k + 1, len(floors))
    if missing and not partial:
        raise ScenarioError("<command line>", "--from", f"{len(missing)} of the {len(floors)} floors' files could not be had, "
                            f"e.g. {missing[0]}; give a folder holding copies (--from DIR), a mirror (--mirror URL), "
                            "or build the split from the floors found (--partial: not official)")
    if not got:
        raise ScenarioError("<command line>", "--from", f"none of the {len(floors)} floors' files could be had, e.g. {missing[0]}")
    # the floors found and the sources they were named by: a cache built from another sources.json is not reused
    key = hashlib.sha256(json.dumps(sorted(got)).encode() + sources_file(suite.name).read_bytes()).hexdigest()[:16]
    folder = cache_dir() / "bench" / suite.name / f"val-{key}"
    if not (folder / "suite.json").is_file():
        tmp = folder.with_name(f"{folder.name}.{os.getpid()}.tmp")
        shutil.rmtree(tmp, ignore_errors=True)
        try:
            built = [_built(suite, fl, got[fl["id"]], tmp) for fl in floors if fl["id"] in got]
            write_manifest(suite, "val", tmp, built)
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)  # a failed build leaves nothing behind
            raise
        folder.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.rename(tmp, folder)
        except OSError:
            shutil.rmtree(tmp, ignore_errors=True)
    (folder.parent / "current").write_text(folder.name + "\n")
    return read_split(suite, "val", folder), missing


def is_fetched(suite: Suite) -> bool:
    try:
        fetched_folder(suite)
    except ScenarioError:
        return False
    return True
