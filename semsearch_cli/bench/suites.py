"""semsearch-bench's suites: frozen, versioned sets of floors (or rooms, or offices) and episodes.

A suite has splits. A split is a folder of floors, each a scenario folder (``scenario.yaml``, its
map, its signs and ``episodes.csv``: the start/goal problems every planner meets), listed in the
split's ``suite.json``. Its **hash** names its content: the SHA-256 of the suite's name, the split,
the repeats per episode and each floor's scenario with every file it names standing for the
SHA-256 of its content (a map image's decoded pixels, any other file's bytes; its planners, which
a bench run sets, left out). Two splits with one hash
hold the same floors and episodes, wherever their files lie.

``val`` splits are shipped with semsearch (package data, ``semsearch_cli/data/bench``). A
``test`` split is drawn by the same generator from a secret **salt** that the project's
maintainers hold, never this repository: only its hash is published (:data:`PUBLISHED`), and a
test split is *official* only when its hash is the published one.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import cv2
import numpy as np
import yaml

from ..errors import ScenarioError, did_you_mean
from ..files import atomic_text, cache_dir
from ..runner.specs import files_by_content

DATA = Path(__file__).resolve().parents[1] / "data" / "bench"
FORMAT = 1  # of suite.json


@dataclass(frozen=True)
class Suite:
    """A suite: ``kind`` of search, ``repeats`` of each episode per planner, its ``splits``, which
    of them are shipped, and ``make(split, salt, out)``, which builds a split's folder (the
    generator, or the shipped scenarios it freezes)."""

    name: str
    kind: str
    summary: str
    repeats: int
    splits: tuple[str, ...]
    shipped: tuple[str, ...]
    make: Callable[[str, str, Path], None] | None = field(default=None, compare=False, repr=False)
    hidden: tuple[str, ...] = ()  # splits drawn from a secret salt
    fetched: bool = False  # made of floors that may not be shipped: built by `semsearch bench fetch` (bench/real.py)
    labels: str | None = None  # the scenario key of the file whose labels --numbering permutes (None: no labels)


SUITES: dict[str, Suite] = {}

# the published hashes (:func:`split_hash`) of each suite's splits. A hidden split's is filled in by
# a maintainer who holds its salt (`semsearch bench hash SUITE --split test --salt-file F`); until
# then it is None and no test split is official.
PUBLISHED: dict[tuple[str, str], str | None] = {}


def register(suite: Suite, hashes: dict[str, str | None]) -> Suite:
    SUITES[suite.name] = suite
    for split in suite.splits:
        PUBLISHED[(suite.name, split)] = hashes.get(split)
    return suite


def suite_named(name: str) -> Suite:
    if name not in SUITES:
        raise ScenarioError("<command line>", "SUITE", f"no suite {name!r}{did_you_mean(name, SUITES)}; "
                            f"suites: {', '.join(SUITES)} (semsearch bench list)")
    return SUITES[name]


def is_official(suite: str, split: str, hash_: str) -> bool:
    """Whether results on ``suite``'s ``split`` of hash ``hash_`` are official: that split has a
    published hash and it is this one. The one rule, for a split built here (:attr:`Split.official`)
    and for rows read back (the board: their ``suite_hash``)."""
    published = PUBLISHED.get((suite, split))
    return published is not None and str(hash_) == published


@dataclass(frozen=True)
class Floor:
    """One floor of a split: its id (``f007``), its scenario file and how it was made."""

    id: str
    scenario: Path
    recipe: dict


@dataclass(frozen=True)
class Split:
    """A split on disk: its suite, name, folder, floors and hash; ``official`` when the hash is
    the published one."""

    suite: Suite
    name: str
    folder: Path
    floors: tuple[Floor, ...]
    hash: str

    @property
    def published(self) -> str | None:
        return PUBLISHED.get((self.suite.name, self.name))

    @property
    def official(self) -> bool:
        return is_official(self.suite.name, self.name, self.hash)

    def floor(self, floor_id: str) -> Floor:
        for f in self.floors:
            if f.id == floor_id:
                return f
        raise ScenarioError(str(self.folder / "suite.json"), "floors", f"no floor {floor_id!r} in {self.suite.name} {self.name}")


IMAGES = (".png", ".pgm", ".bmp", ".jpg", ".jpeg")


def _content(d, base: Path):
    """``d`` with each string that names a file beside the scenario replaced by the hash of its
    content: an image's by its pixels (its shape and values as decoded: two PNG encoders' bytes
    for one map hash alike), any other file's by its bytes."""
    if isinstance(d, dict):
        return {k: _content(v, base) for k, v in d.items()}
    if isinstance(d, list):
        return [_content(v, base) for v in d]
    if isinstance(d, str) and d.lower().endswith(IMAGES) and (base / d).is_file():
        img = cv2.imread(str(base / d), cv2.IMREAD_UNCHANGED)
        if img is not None:
            return "pixels:" + hashlib.sha256(repr(img.shape).encode() + np.ascontiguousarray(img).tobytes()).hexdigest()
    return files_by_content(d, base)


def scenario_content(path: Path) -> dict:
    """A floor's scenario as the hash sees it: the YAML document without its planners, each file
    it names replaced by the hash of its content (:func:`_content`)."""
    doc = yaml.safe_load(path.read_text())
    doc.pop("planners", None)
    return _content(doc, path.parent)


def split_hash(suite: Suite, split: str, floors) -> str:
    """The SHA-256 (hex) of a split's content (see the module docstring)."""
    content = {"suite": suite.name, "split": split, "repeats": suite.repeats,
               "floors": [{"id": f.id, "scenario": scenario_content(f.scenario)} for f in floors]}
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()


MAX_SALT_BYTES = 4096  # a salt is a few dozen characters (secrets.token_hex(32): 64)


def read_salt(salt_file: str | Path) -> str:
    """A salt file's text (stripped). Refused when it is not a regular file (a FIFO with no
    writer would block the read forever; a folder, a device), larger than
    :data:`MAX_SALT_BYTES`, not UTF-8, or shorter than 16 characters: each before it is read, and
    the file is opened without blocking, so nothing that takes its place in between can hang it."""
    p = Path(salt_file)
    try:
        st = os.stat(p)
    except OSError as exc:
        raise ScenarioError(str(p), "", f"cannot read the salt file ({exc.strerror or exc})") from None
    if not stat.S_ISREG(st.st_mode):
        what = ("a FIFO" if stat.S_ISFIFO(st.st_mode) else "a folder" if stat.S_ISDIR(st.st_mode) else
                "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else "a socket" if stat.S_ISSOCK(st.st_mode)
                else "not a file")
        raise ScenarioError(str(p), "", f"the salt file is {what}, not a regular file: give the file holding the salt")
    if st.st_size > MAX_SALT_BYTES:
        raise ScenarioError(str(p), "", f"a salt file of {st.st_size:,} bytes; a salt is at most {MAX_SALT_BYTES:,} "
                            "(e.g. python -c 'import secrets; print(secrets.token_hex(32))')")
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise ScenarioError(str(p), "", "the salt file is not a regular file: give the file holding the salt")
            data = fh.read(MAX_SALT_BYTES + 1)
        if len(data) > MAX_SALT_BYTES:
            raise ScenarioError(str(p), "", f"a salt file of more than {MAX_SALT_BYTES:,} bytes; a salt is at most "
                                f"{MAX_SALT_BYTES:,}")
        salt = data.decode("utf-8").strip()
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(str(p), "", f"cannot read the salt file ({getattr(exc, 'strerror', None) or exc})") from None
    if len(salt) < 16:
        raise ScenarioError(str(p), "", f"a salt of {len(salt)} characters; a hidden split's salt has at least 16 "
                            "(e.g. python -c 'import secrets; print(secrets.token_hex(32))')")
    return salt


def read_split(suite: Suite, split: str, folder: Path) -> Split:
    """The split written in ``folder`` (its suite.json and floors), hashed."""
    f = folder / "suite.json"
    try:
        man = json.loads(f.read_text())
    except (OSError, ValueError) as exc:
        raise ScenarioError(str(f), "", f"cannot read the split's manifest ({exc})") from None
    if man.get("suite") != suite.name or man.get("split") != split or man.get("format") != FORMAT:
        raise ScenarioError(str(f), "suite", f"holds {man.get('suite')} {man.get('split')} (format {man.get('format')}), "
                            f"not {suite.name} {split} (format {FORMAT})")
    floors = tuple(Floor(x["id"], folder / x["id"] / "scenario.yaml", x.get("recipe", {})) for x in man["floors"])
    missing = [fl.id for fl in floors if not fl.scenario.is_file()]
    if missing:
        raise ScenarioError(str(folder), "floors", f"floor {missing[0]} has no scenario.yaml ({len(missing)} missing)")
    return Split(suite, split, folder, floors, split_hash(suite, split, floors))


def write_manifest(suite: Suite, split: str, folder: Path, floors: list[tuple[str, dict]]) -> Split:
    """Write ``folder/suite.json`` for ``floors`` ((id, recipe), their folders already written)
    and return the split, hashed."""
    man = {"suite": suite.name, "split": split, "format": FORMAT, "kind": suite.kind, "repeats": suite.repeats,
           "floors": [{"id": i, "recipe": r} for i, r in floors]}
    atomic_text(folder / "suite.json", json.dumps(man, indent=1) + "\n")
    return read_split(suite, split, folder)


def open_split(name: str, split: str = "val", salt_file: str | Path | None = None) -> Split:
    """A suite's split: a shipped one from the package; a hidden one (``test``) built from the
    salt in ``salt_file`` (once, into :func:`cache_dir`)."""
    suite = suite_named(name)
    if split not in suite.splits:
        raise ScenarioError("<command line>", "--split", f"{name} has no split {split!r}; its splits: {', '.join(suite.splits)}")
    if suite.fetched:
        if salt_file is not None:
            raise ScenarioError("<command line>", "--salt-file", f"{name} is public (fetched by its sources); a salt goes "
                                "with a hidden split")
        return read_split(suite, split, fetched_folder(suite))
    if split in suite.hidden:
        if salt_file is None:
            raise ScenarioError("<command line>", "--salt-file", f"{name} {split} is drawn from a secret salt that the "
                                "project's maintainers hold: give it with --salt-file F (a submitter runs --split val; "
                                "docs/bench.md says how a test score is made)")
        salt = read_salt(salt_file)
        folder = cache_dir() / "bench" / name / f"{split}-{hashlib.sha256(salt.encode()).hexdigest()[:16]}"
        if not (folder / "suite.json").is_file():
            build(suite, split, salt, folder)
        return read_split(suite, split, folder)
    if salt_file is not None:
        raise ScenarioError("<command line>", "--salt-file", f"{name} {split} is public; a salt goes with a hidden split "
                            f"({', '.join(suite.hidden) or 'this suite has none'})")
    return read_split(suite, split, DATA / name / split)


def fetched_folder(suite: Suite) -> Path:
    """The split folder the last ``semsearch bench fetch`` of ``suite`` built, or a
    :class:`ScenarioError` saying to fetch it."""
    cur = cache_dir() / "bench" / suite.name / "current"
    folder = cur.parent / cur.read_text().strip() if cur.is_file() else None
    if folder is None or not (folder / "suite.json").is_file():
        raise ScenarioError("<command line>", "SUITE", f"{suite.name} is made of floors that semsearch may not ship: "
                            f"fetch them first, semsearch bench fetch {suite.name} [--from DIR]")
    return folder


def build(suite: Suite, split: str, salt: str, folder: Path) -> None:
    """Build a split into ``folder`` (written aside and renamed into place, so a half-built split
    is never read)."""
    tmp = folder.with_name(f"{folder.name}.{os.getpid()}.tmp")
    suite.make(split, salt, tmp)
    folder.parent.mkdir(parents=True, exist_ok=True)
    try:
        os.rename(tmp, folder)
    except OSError:  # another process built it first: the same split
        shutil.rmtree(tmp, ignore_errors=True)
