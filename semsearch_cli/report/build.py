"""`semsearch report`: one document rebuilt from the rows of one or several results folders, with
a section per kind of search found in them (the sections are the only place that knows the kinds'
tables and figures). Tables come from runs.csv alone; figures that need the map (paths, heat maps,
the replay) also load the scenario named in each folder's meta.json, and are skipped, with a note,
when it is gone."""

from __future__ import annotations

import datetime
import hashlib
import json
import os
import re
import shlex
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from .. import __version__
from .. import provenance
from ..errors import ScenarioError
from ..planners import code_of
from ..files import check_outputs, read_user_text
from ..runner import Loaded, read_runs, run_rows
from ..tasks.episodes import set_hash
from . import doors, objects, chain, indirect  # noqa: F401  (each registers its section)
from ..plugins import load_kinds
from .sections import SECTIONS, replaying
from .stats import episodes
from .tables import cost_table, goal_key, planner_order
from .document import Code, Document, atomic_text
from .runfiles import same_goal

ABSOLUTE = re.compile(r"(?<![\w.])/[^\s:;,()'\"]+")  # an absolute path in a message (a report names none)
ALL_FORMATS = ("md", "csv", "png", "pdf", "svg", "html")  # png, pdf, svg: every figure (GIF replays stay GIF)


@dataclass(frozen=True)
class ReplayChoice:
    """The run to replay (``--replay PLANNER,GOAL,EPISODE,SEED``)."""

    planner: str
    goal: str
    episode: int
    seed: int


_WHOLE = re.compile(r"[0-9]{1,18}", re.ASCII)  # an episode or a seed: ASCII digits, 64-bit (never ², never --1)


def parse_replay(text: str) -> ReplayChoice:
    """``PLANNER,GOAL,EPISODE,SEED`` (split from the right: a planner label may hold commas)."""
    parts = [p.strip() for p in str(text).rsplit(",", 3)]
    if len(parts) != 4 or not all(parts) or not _WHOLE.fullmatch(parts[2]) or not _WHOLE.fullmatch(parts[3]):
        raise ScenarioError("<command line>", "--replay", f"expected PLANNER,GOAL,EPISODE,SEED with whole numbers for "
                            f"the episode and the seed (e.g. greedy,76,0,3), got {text!r}")
    return ReplayChoice(parts[0], parts[1], int(parts[2]), int(parts[3]))


def check_replay(choice: ReplayChoice, parts_by_kind: dict) -> None:
    """A :class:`ScenarioError` naming ``--replay`` and listing the runs there are, unless some
    folder of a kind with a replay holds the chosen run."""
    rows = [run_rows(p.runs) for k in replaying() for p in parts_by_kind.get(k, [])]
    rows = pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(columns=["planner", "goal", "seed"])
    ep = episodes(rows)
    hit = (rows["planner"].astype(str) == choice.planner) & rows["goal"].map(lambda g: same_goal(g, choice.goal)) \
        & (ep == choice.episode) & (pd.to_numeric(rows["seed"]) == choice.seed)
    if len(rows) and hit.any():
        return
    if not len(rows):
        raise ScenarioError("<command line>", "--replay", f"these folders hold no runs of a kind with a replay "
                            f"({', '.join(replaying())}); leave --replay out")

    def span(v):
        v = sorted(set(int(x) for x in v))
        return f"{v[0]}-{v[-1]}" if len(v) > 2 and v[-1] - v[0] == len(v) - 1 else ", ".join(map(str, v))

    seen = {"planner": rows["planner"].astype(str) == choice.planner,
            "goal": rows["goal"].map(lambda g: same_goal(g, choice.goal)), "episode": ep == choice.episode}
    missing = [k for k, m in seen.items() if not m.any()]
    why = f"no such {' or '.join(missing)}" if missing else "no run has all four together"
    goals = sorted(rows["goal"].astype(str).unique(), key=goal_key)
    per_goal = {g: span(ep[rows["goal"].astype(str) == g]) for g in goals}
    eps = "; ".join(f"goal {g}: {e}" for g, e in per_goal.items()) if len(goals) <= 12 else span(ep)
    raise ScenarioError("<command line>", "--replay", f"no run {choice.planner},{choice.goal},{choice.episode},{choice.seed} "
                        f"(PLANNER,GOAL,EPISODE,SEED) in these rows ({why}). They hold planners "
                        f"{', '.join(planner_order(rows['planner'].astype(str)))}; goals {', '.join(goals)}; episodes "
                        f"({eps}); seeds {span(rows['seed'])}. Give one of those, or --no-replay.")


def write_meta(out_dir: Path, loaded: Loaded, varied: dict | None = None) -> None:
    """Record, beside runs.csv, what produced (or extended) it: the commands, the scenario (its
    path relative to the folder, the hash of its bytes, its fingerprint and its episode set),
    each planner's code (:func:`~semsearch_cli.planners.code_of`), and semsearch's version, code
    hash, git commit and the versions of Python and the libraries (:mod:`semsearch_cli.provenance`)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    f = out_dir / "meta.json"
    meta = read_meta(out_dir)
    meta.setdefault("commands", [])
    scenario = Path(loaded.path).resolve()
    meta["scenario"] = os.path.relpath(scenario, out_dir.resolve())
    meta["scenario_sha256"] = hashlib.sha256(scenario.read_bytes()).hexdigest()
    if varied is not None:  # a sweep's value: the scenario with this parameter set (semsearch verify loads it so)
        meta["varied"] = varied
    meta["fingerprint"] = loaded.fingerprint
    eps = loaded.task.episodes
    meta["episodes"] = {"count": len(eps), "hash": set_hash(eps)}
    planners = {}
    for v in loaded.task.variants():
        code = code_of(v)
        if "file" in code:
            code["file"] = os.path.relpath(code["file"], out_dir.resolve())
        planners[v.label] = code
    meta["planners"] = planners
    meta["semsearch"] = provenance.describe()
    cmd = "semsearch " + " ".join(shlex.quote(a) for a in sys.argv[1:]) if Path(sys.argv[0]).name == "semsearch" else " ".join(sys.argv)
    if cmd not in meta["commands"]:
        meta["commands"].append(cmd)
    atomic_text(f, json.dumps(meta, indent=2))


def scenario_of(folder: Path, meta: dict) -> Path | None:
    """The scenario file meta.json names (relative to the folder, or absolute as earlier
    versions wrote it); None when it names none or the file is gone."""
    if not meta.get("scenario"):
        return None
    p = Path(meta["scenario"])
    p = p if p.is_absolute() else Path(folder) / p
    return p if p.is_file() else None


def relative(path, base) -> str:
    """``path`` as the report shows it: relative to the folder ``base`` (``.`` for the folder
    itself), in forward slashes, so that no absolute path of the machine that wrote the report
    is in it."""
    rel = os.path.relpath(os.path.abspath(path), os.path.abspath(base))  # symbolic links kept as named
    return Path(rel).as_posix()


def shown_command(cmd: str, folder) -> str:
    """A command recorded in meta.json as the report shows it: each argument that is an absolute
    path (or ``--opt=/abs/path``) made relative to the results ``folder``; the others as typed."""
    try:
        words = shlex.split(cmd)
    except ValueError:
        return cmd
    out = []
    for w in words:
        key, eq, value = w.partition("=") if w.startswith("-") else ("", "", w)
        if os.path.isabs(value):
            value = relative(value, folder)
        out.append(shlex.quote(key + eq + value))
    return " ".join(out)


def provenance_table(meta: dict, folder=None) -> pd.DataFrame:
    """What meta.json says made the rows, one line per fact (for the end of report.md); with
    ``folder`` (the results folder), paths meta.json holds absolute (written by earlier versions)
    are shown relative to it."""
    def path(p):
        return relative(p, folder) if folder is not None and p and os.path.isabs(str(p)) else p

    sem = meta.get("semsearch")
    rows = []
    if isinstance(sem, dict):
        rows += [("semsearch", f"{sem.get('version')} (code {sem.get('code')})"), ("git commit", sem.get("commit") or "not from a checkout")]
        rows += [(k, v) for k, v in sem.items() if k not in ("version", "code", "commit")]
    elif sem:
        rows.append(("semsearch", str(sem)))
    for key in ("scenario", "scenario_sha256", "fingerprint"):
        if meta.get(key):
            rows.append((key, path(meta[key]) if key == "scenario" else meta[key]))
    if isinstance(meta.get("episodes"), dict):
        rows.append(("episodes", f"{meta['episodes'].get('count')} (set hash {meta['episodes'].get('hash')})"))
    for label, code in (meta.get("planners") or {}).items():
        if isinstance(code, dict):
            what = code.get("source", "")
            what += f" {path(code['file'])}" if code.get("file") else ""
            what += f" {code['distribution']}" if code.get("distribution") else ""
            rows.append((f"planner {label}", f"code {code.get('hash')} ({what.strip()})"))
    return pd.DataFrame(rows, columns=["what", "value"]).set_index("what")


def read_meta(folder: Path) -> dict:
    """A results folder's meta.json ({} when there is none); a :class:`ScenarioError` when it is
    not a JSON object with a list of commands (it is ours: a damaged one is for the user to move
    away, not for us to overwrite)."""
    f = Path(folder) / "meta.json"
    if not f.exists():
        return {}
    try:
        meta = json.loads(read_user_text(f, "meta.json"))
    except json.JSONDecodeError as exc:
        meta = exc
    if not isinstance(meta, dict) or not isinstance(meta.get("commands", []), list) \
            or not isinstance(meta.get("scenario", ""), str):
        raise ScenarioError(str(f), "", "not the JSON semsearch writes (the scenario's path and the commands run here); "
                            "move it away or delete it, and run again")
    return meta


@dataclass
class Part:
    """The rows of one results folder (of one kind), with its meta.json."""

    folder: Path
    runs: pd.DataFrame
    meta: dict
    _loaded: object = field(default=None, repr=False)
    home: Path | None = None  # the report's folder: the paths the report names are relative to it

    @property
    def shown(self) -> str:
        """The folder as the report names it: relative to the report's folder."""
        return relative(self.folder, self.home) if self.home is not None else str(self.folder)

    def loaded(self, notes: list, what: str):
        """The scenario named in meta.json, loaded (once), or None with a note saying that
        ``what`` were skipped and why (the folder named as :attr:`shown`)."""
        name = self.shown
        if self._loaded is None:
            path = scenario_of(self.folder, self.meta)
            if path is None:
                self._loaded = f"the scenario file named in {'' if name == '.' else name + '/'}meta.json is not available"
            else:
                try:
                    self._loaded = Loaded.load(path)
                except ScenarioError as exc:
                    # an absolute path in the message (a map that has gone, where it was looked for): relative
                    # to the report's folder, as every path the report names
                    self._loaded = ABSOLUTE.sub(lambda m: relative(m.group(0), self.home or self.folder), str(exc))
        if isinstance(self._loaded, str):
            notes.append(f"{what} of {'these rows' if name == '.' else name} were skipped: {self._loaded}.")
            return None
        return self._loaded


def build_report(folders: list[Path], out: Path | None = None, formats=ALL_FORMATS, replay=True) -> list[Path]:
    """Write tables (CSV, Markdown), figures (PNG, PDF, SVG as ``formats`` asks; PNG whenever the
    documents are written; GIF replays) and one report.md / report.html for the rows of all
    ``folders`` (into ``out``; default: the folder itself when there is one, else
    ``results/report``). ``replay``: False (none), True (each section's default run) or the run to
    replay (a :class:`ReplayChoice` or its ``PLANNER,GOAL,EPISODE,SEED`` text), checked against
    the rows before anything is written. Returns the report files written."""
    load_kinds()  # the sections of the kinds installed packages add
    if isinstance(replay, str):
        replay = parse_replay(replay)
    t0 = time.perf_counter()
    folders = [Path(f) for f in folders]
    seen: dict = {}
    for f in folders:  # the same folder twice counted its rows twice, in every table and test
        key = f.resolve()
        if key in seen:
            raise ScenarioError("<command line>", "FOLDERS", f"{f} is given twice (as {seen[key]} too): its rows would "
                                "count twice; give each results folder once")
        seen[key] = f
    out = Path(out) if out is not None else folders[0] if len(folders) == 1 else Path("results") / "report"
    parts_by_kind: dict[str, list[Part]] = {}
    metas = {str(f): read_meta(f) for f in folders}
    total = 0
    for folder in folders:
        runs = read_runs(folder / "runs.csv")
        if runs.empty:
            raise ScenarioError(str(folder / "runs.csv"), "", "no finished runs to report (is this a semsearch results folder?)")
        meta = metas[str(folder)]
        total += len(runs)
        for kind, rows in runs.groupby("kind", sort=False):
            if kind not in SECTIONS:
                raise ScenarioError(str(folder / "runs.csv"), "kind", f"unknown kind {kind!r}; known: {', '.join(SECTIONS)}")
            parts_by_kind.setdefault(kind, []).append(Part(folder, rows.reset_index(drop=True), meta, home=out))
    if isinstance(replay, ReplayChoice):
        check_replay(replay, parts_by_kind)
    out.mkdir(parents=True, exist_ok=True)
    check_outputs(out, ("report.md", "report.html"), ("tables", "figures"))
    (out / "tables").mkdir(exist_ok=True)
    (out / "figures").mkdir(exist_ok=True)
    formats = set(formats)
    doc = Document()
    scen = sorted({s for ps in parts_by_kind.values() for p in ps for s in p.runs["scenario"].astype(str).unique()})
    title = f"semsearch report: {', '.join(scen)}"
    doc.heading(1, title)
    now = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    doc.para(f"semsearch {__version__}, {now}; {total} rows from ",
             *[x for f in folders for x in (Code(relative(f / "runs.csv", out)), " ")],
             f"({', '.join(f'{k}: {sum(len(p.runs) for p in ps)}' for k, ps in parts_by_kind.items())}). Paths are "
             "relative to this report's folder.")
    notes: list[str] = []
    for kind, parts in parts_by_kind.items():
        SECTIONS[kind].section(doc, parts, out, formats, replay, notes)
    costs = cost_table(pd.concat([p.runs for ps in parts_by_kind.values() for p in ps], ignore_index=True))
    if len(costs):  # a planner that pays for its decisions (a language model), whatever the kind
        doc.heading(2, "What the planners' decisions cost")
        doc.para("Summed over each planner's runs (the rows' llm_calls, tokens_in, tokens_out, invalid_replies, "
                 "fallbacks, llm_s): calls to the language model, tokens as its server counted them, replies that "
                 "could not be taken, decisions taken by the fallback (the nearest target), seconds waiting for replies.")
        doc.table(costs)
        atomic_text(out / "tables" / "costs.csv", costs.to_csv(index=False))
    here = [relative(f, out) for f in folders]
    rebuild = "semsearch report " + " ".join(shlex.quote(f) for f in here) + ("" if here == ["."] else " --out .")
    for folder, meta in metas.items():
        name = relative(folder, out)
        doc.heading(2, "How these rows were produced" if name == "." else f"How {name} was produced")
        if name != ".":
            doc.para(f"Paths in this section are relative to {name}.")
        if meta.get("commands"):
            doc.para("The commands that wrote the rows (an absolute path typed in them shown relative to the "
                     "results folder):")
            doc.code("\n".join(shown_command(c, folder) for c in meta["commands"]))
        doc.para("Rebuild this report, from its folder: ", Code(rebuild))
        scenario = scenario_of(Path(folder), meta)
        if scenario is not None:
            doc.para("Scenario ", Code(relative(scenario, folder)), ":")
            doc.code(scenario.read_text(errors="replace").strip(), "yaml")
        prov = provenance_table(meta, folder)
        if len(prov):
            doc.para("Provenance (meta.json): the code, the versions and the inputs these rows were made with.")
            doc.table(prov)
    for n in notes:
        doc.note(n)
    files = []
    if formats & {"md", "html"}:
        atomic_text(out / "report.md", doc.markdown(out))
        files.append(out / "report.md")
    if "html" in formats:
        atomic_text(out / "report.html", doc.html(title))
        files.append(out / "report.html")
    print(f"report of {', '.join(map(str, folders))}: {total} rows, {doc.figures} figures, {time.perf_counter() - t0:.1f} s",
          file=sys.stderr)
    return files


def console_tables(runs: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    """(title, table) per kind in ``runs``: what `semsearch run` prints when it finishes."""
    return [t for kind, rows in runs.groupby("kind", sort=False) for t in SECTIONS[kind].console(rows)]


def show(loaded: Loaded, out: Path) -> Path:
    """Draw a scenario without simulating, as its kind's section draws it."""
    SECTIONS[loaded.kind].show(loaded, out)
    return out
