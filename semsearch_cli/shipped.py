"""The scenarios and maps shipped with semsearch, as package data: ``semsearch_cli/data/configs``
(the scenarios, each naming its map and signs relative to its own file) and
``semsearch_cli/data/maps``. A checkout's ``configs/`` and ``maps/`` are links to them, so
``semsearch run configs/hotel.yaml`` in a checkout and ``semsearch run hotel`` from any folder
after a wheel install run the same files.

A scenario argument is a file when one exists at that path; otherwise a bare name (no folder, no
suffix) is a shipped scenario's. ``semsearch init NAME DIR`` copies a shipped scenario and the
files it names into a folder of the user's, to edit."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import yaml

from .errors import ScenarioError, did_you_mean
from .files import atomic_text

DATA = Path(__file__).resolve().parent / "data"
CONFIGS = DATA / "configs"
MAPS = DATA / "maps"


def names() -> list[str]:
    """The shipped scenarios' names (``hotel``, ``demo``, ...), sorted."""
    return sorted(p.stem for p in CONFIGS.glob("*.yaml"))


def describe(name: str) -> str:
    """A shipped scenario's header comment (what it is), as one paragraph, or ``""``."""
    lines = []
    for line in path(name).read_text().splitlines():
        if not line.startswith("#"):
            break
        if "yaml-language-server" not in line:
            lines.append(line.lstrip("#").strip())
    return " ".join(lines)


def path(name: str) -> Path:
    """The file of the shipped scenario ``name``, or a :class:`ScenarioError` listing them."""
    p = CONFIGS / f"{name}.yaml"
    if not p.is_file() or "/" in name or name.startswith("."):
        raise ScenarioError("<command line>", "scenario", f"{name!r} is neither a file nor a shipped scenario"
                            f"{did_you_mean(name, names())}; shipped: {', '.join(names())} (semsearch scenarios)")
    return p


def is_name(text: str | Path) -> bool:
    """Whether a scenario argument reads as a shipped scenario's name rather than a path: no
    folder, no suffix, and no file of that name in the working folder."""
    s = str(text)
    return bool(re.fullmatch(r"[A-Za-z0-9_-]+", s)) and not Path(s).exists()


def scenario_file(scenario: str | Path) -> Path:
    """A scenario argument as a file's path: the path itself, or the shipped scenario it names
    (:func:`is_name`)."""
    return path(str(scenario)) if is_name(scenario) else Path(scenario)


def _named_files(doc, base: Path) -> set[str]:
    """The strings of a YAML document that name an existing file relative to ``base``."""
    found = set()
    if isinstance(doc, dict):
        for v in doc.values():
            found |= _named_files(v, base)
    elif isinstance(doc, list):
        for v in doc:
            found |= _named_files(v, base)
    elif isinstance(doc, str) and doc and (base / doc).is_file():
        found.add(doc)
    return found


def init(name: str, dest: str | Path, force: bool = False) -> list[Path]:
    """Copy the shipped scenario ``name`` into the folder ``dest`` to edit: ``dest/NAME.yaml``, the
    files it names (maps under ``dest/maps/``, others beside it) and the JSON Schema its first line
    names; the scenario's paths are rewritten to the copies. Returns the files written. Refuses to
    overwrite a file unless ``force``."""
    src = path(name)
    dest = Path(dest)
    text = src.read_text()
    copies: dict[Path, Path] = {}
    for ref in sorted(_named_files(yaml.safe_load(text), src.parent)):
        full = (src.parent / ref).resolve()
        rel = full.relative_to(DATA) if full.is_relative_to(MAPS) else Path(full.name)
        copies[full] = dest / rel
        if ref != rel.as_posix():
            text = re.sub(rf"(?<![\w./-]){re.escape(ref)}(?![\w./-])", rel.as_posix(), text)
    schema = CONFIGS / "scenario.schema.json"
    copies[schema] = dest / schema.name
    target = dest / f"{name}.yaml"
    clash = [p for p in [target, *copies.values()] if p.exists()] if not force else []
    if clash:
        raise ScenarioError(str(clash[0]), "", "already exists: choose an empty folder, or pass --force to overwrite")
    for s, d in copies.items():
        d.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(s, d)
    atomic_text(target, text)
    return [target, *copies.values()]
