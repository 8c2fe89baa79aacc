"""The scenarios and maps shipped with semsearch, as package data: ``semsearch_cli/data/configs``
(the scenarios, each naming its map and signs relative to its own file) and
``semsearch_cli/data/maps``. A checkout's ``configs/`` and ``maps/`` are links to them, so
``semsearch run configs/hotel.yaml`` in a checkout and ``semsearch run hotel`` from any folder
after a wheel install run the same files.

A scenario argument is a file when one exists at that path; otherwise a bare name (no folder, no
suffix) is a shipped scenario's. ``semsearch init NAME DIR`` copies a shipped scenario and the
files it names into a folder of the user's, to edit."""

from __future__ import annotations

import filecmp
import re
import shutil
from pathlib import Path

import yaml

from .errors import ScenarioError, did_you_mean
from .files import atomic_text

DATA = Path(__file__).resolve().parent / "data"
CONFIGS = DATA / "configs"
MAPS = DATA / "maps"
NAME = r"[A-Za-z0-9_-]+"  # a shipped scenario's name: no folder, no suffix


def names() -> list[str]:
    """The shipped scenarios' names (``hotel``, ``demo``, ...), sorted."""
    return sorted(p.stem for p in CONFIGS.glob("*.yaml"))


def describe(name: str) -> str:
    """What a shipped scenario is: its header comment up to the first line that ends a sentence,
    as one line (``""`` without one)."""
    lines = []
    for line in path(name).read_text().splitlines():
        if not line.startswith("#"):
            break
        if "yaml-language-server" in line:
            continue
        lines.append(line.lstrip("#").strip())
        if lines[-1].endswith("."):
            break
    return re.sub(r"\s*Regenerate with scripts/\S+$", "", " ".join(lines))


def path(name: str, where: str = "<command line>") -> Path:
    """The file of the shipped scenario ``name``, or a :class:`ScenarioError` (naming ``where``
    the name was given) listing them."""
    p = CONFIGS / f"{name}.yaml"
    if not re.fullmatch(NAME, name) or not p.is_file():
        raise ScenarioError(where, "scenario", f"{name!r} is neither a scenario file nor a shipped scenario"
                            f"{did_you_mean(name, names())}; shipped: {', '.join(names())} (semsearch scenarios)")
    return p


def is_name(text: str | Path) -> bool:
    """Whether a scenario argument reads as a shipped scenario's name rather than a path: no
    folder, no suffix, and no file of that name (a folder of that name does not count)."""
    return bool(re.fullmatch(NAME, str(text))) and not Path(text).is_file()


def scenario_file(scenario: str | Path, where: str = "<command line>") -> Path:
    """A scenario argument as a file's path: the file itself, or the shipped scenario it names
    (:func:`is_name`). A name that is also ``NAME.yaml`` in the working folder (a copy made by
    ``semsearch init NAME .``) is refused as ambiguous, naming both."""
    if not is_name(scenario):
        return Path(scenario)
    own = Path(f"{scenario}.yaml")
    if own.is_file() and str(scenario) in names():
        raise ScenarioError(where, "scenario", f"{str(scenario)!r} is both a shipped scenario and {own} in this folder: give "
                            f"the file, {own}, to run your copy; the shipped one runs by its name from any other folder")
    return path(str(scenario), where)


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
    # a file already there with the same bytes (a map two scenarios share) is no clash
    todo = {s: d for s, d in copies.items() if not (d.is_file() and filecmp.cmp(s, d, shallow=False))}
    clash = [p for p in [target, *todo.values()] if p.exists()] if not force else []
    if clash:
        raise ScenarioError(str(clash[0]), "", "already exists: choose another folder, or pass --force to overwrite")
    try:
        for s, d in todo.items():
            d.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(s, d)
        atomic_text(target, text)
    except OSError as exc:
        raise ScenarioError(str(dest), "", f"cannot copy {name} into it: {exc.strerror or exc}") from None
    return [target, *copies.values()]
