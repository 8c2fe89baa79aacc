"""A catalogue of hostile inputs: every kind of bad input a user (or a damaged disk) can give the
command line, each with what must happen. The tests run the cases that first crashed it in-process
(``test_hostile.py``); ``benchmarks/hostile.py`` runs every case as a real process, with a time
limit, and tabulates the outcomes by category.

A case is refused when it exits with status 2 and no traceback; accepted when it exits 0. A
traceback, another status or running past the time limit is a defect whatever was expected.
"""

from __future__ import annotations

import shutil
import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
import yaml

from semsearch_cli.world.buildings.demo import write_demo

REPO = Path(__file__).resolve().parents[1]
INF, NAN = float("inf"), float("nan")


@dataclass
class Case:
    category: str
    name: str
    args: list[str]
    expect: str = "refuse"  # refuse | accept | fail (exit 1: a check that finds its input wrong) | either (no traceback, no hang)
    issue: bool = False  # a defect found in the first hostile review (the tests run these)
    says: tuple = ()  # text the output must hold (the field or flag blamed, the file named)
    cwd: Path | None = field(default=None, repr=False)


def _dump(path: Path, data) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _set(d: dict, keys: list, value) -> dict:
    out = yaml.safe_load(yaml.safe_dump(d))
    cur = out
    for k in keys[:-1]:
        cur = cur.setdefault(k, {}) if isinstance(k, str) else cur[k]
    cur[keys[-1]] = value
    return out


def _png_header(path: Path, w: int, h: int) -> None:
    """A PNG whose header claims w x h pixels, with no image data to speak of."""
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)
    chunk = struct.pack(">I", len(ihdr)) + b"IHDR" + ihdr + struct.pack(">I", zlib.crc32(b"IHDR" + ihdr))
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk + struct.pack(">I", 0) + b"IEND" + struct.pack(">I", zlib.crc32(b"IEND")))


def demo_base(root: Path) -> tuple[dict, Path]:
    """The demo scenario (door search) with absolute paths, and its folder."""
    d = root / "demo"
    if not (d / "scenario.yaml").is_file():
        write_demo(d)
    base = yaml.safe_load((d / "scenario.yaml").read_text())
    base["map"]["image"] = str(d / "map.png")
    base["doors"] = str(d / "doors.csv")
    base["planners"] = [{"name": "greedy"}]
    base["experiment"] = {"seeds": 1, "max_distance": 300.0}
    return base, d


def check_outcome(case: Case, res, cwd: Path) -> None:
    """The outcome a case must have, from typer's ``CliRunner`` result ``res`` of a command run in
    the empty working folder ``cwd``: no traceback; a refusal exits 2 with an error naming what
    ``case.says``; an acceptance exits 0; nothing written into ``cwd`` unless accepted."""
    assert res.exception is None or isinstance(res.exception, SystemExit), f"{type(res.exception).__name__}: {res.exception}"
    text = " ".join(res.output.split())
    assert "Traceback" not in text
    if case.expect == "refuse":
        assert res.exit_code == 2, text
        assert "error" in text.lower() or "invalid value" in text.lower(), text
    elif case.expect == "accept":
        assert res.exit_code == 0, text
    elif case.expect == "fail":  # a check that finds what it checks wrong (verify of a falsified folder): exit 1, said
        assert res.exit_code == 1, text
    else:
        assert res.exit_code in (0, 2), text
    for s in case.says:
        assert s in text, f"{s!r} not in: {text}"
    assert list(cwd.iterdir()) == [] or case.expect in ("accept", "fail"), sorted(p.name for p in cwd.iterdir())


def build_cases(root: Path) -> list[Case]:
    """Every case, its files written under ``root``."""
    root.mkdir(parents=True, exist_ok=True)
    base, demo = demo_base(root)
    good = _dump(root / "good.yaml", base)
    cases: list[Case] = []

    def scen(name: str, data, **kw) -> Path:
        return _dump(root / "scen" / f"{name}.yaml", data)

    def add(category, name, args, expect="refuse", issue=False, says=()):
        cases.append(Case(category, name, [str(a) for a in args], expect, issue, tuple(says)))

    # -- numbers: every numeric field of the three kinds of search, given garbage
    office = yaml.safe_load((REPO / "configs" / "office.yaml").read_text())
    office["map"]["image"] = str(REPO / "maps" / "office" / "map.png")
    office["planners"] = [{"name": "lsos"}]
    office["objects"]["cases"] = office["objects"]["cases"][:1]
    indirect = {"name": "ind", "indirect": {"rooms": {"count": 2, "seed": 0}, "time_limit": 30}, "planners": [{"name": "UIS"}],
                "experiment": {"seeds": 1}}
    door_fields = ["map.resolution", "map.origin.0", "start.x", "start.y", "start.heading", "robot.radius", "robot.step",
                   "laser.fov", "laser.beams", "laser.range", "laser.noise_std", "door_camera.fov", "door_camera.range",
                   "door_camera.p_read", "door_camera.p_misread", "belief.visited_radius", "belief.density_radius",
                   "belief.density_delta", "belief.min_reads", "belief.himm_max", "navigation.replan_every",
                   "experiment.seeds", "experiment.base_seed", "experiment.max_distance", "experiment.max_steps"]
    object_fields = ["objects.camera.range", "objects.camera.fov", "objects.camera.p_detect", "objects.places.0.x",
                     "objects.places.0.facing", "objects.recording_hours.0", "objects.requests.0.hour"]
    indirect_fields = ["indirect.time_limit", "indirect.resolution", "indirect.replan_every", "indirect.view_scales.0",
                       "indirect.camera.secondary_range", "indirect.camera.fps", "indirect.robot.speed",
                       "indirect.robot.radius", "indirect.rooms.size.0", "indirect.p_outside"]
    # first found: .inf (and 1e9) crashed ranges, radii and the budget; NaN went through headings, facings, places
    issue_numbers = {f: ("inf", "1e9") for f in ("door_camera.range", "laser.range", "objects.camera.range", "experiment.max_distance",
                                                 "belief.visited_radius", "belief.density_radius")}
    issue_numbers |= {f: ("nan",) for f in ("start.heading", "objects.places.0.facing", "objects.places.0.x")}
    values = [("inf", INF, "refuse"), ("-inf", -INF, "refuse"), ("nan", NAN, "refuse"), ("1e9", 1e9, "either"),
              ("-1", -1, "either"), ("text", "abc", "refuse")]
    for kind, doc, fields in (("doors", base, door_fields), ("objects", office, object_fields), ("indirect", indirect, indirect_fields)):
        for f in fields:
            keys = [int(k) if k.isdigit() else k for k in f.split(".")]
            if kind == "indirect" and keys[:2] == ["indirect", "rooms"]:
                doc2 = _set(doc, ["indirect", "rooms", "size"], [6.0, 6.0])
            elif f == "map.origin.0":
                doc2 = _set(doc, ["map", "origin"], [0.0, 0.0])
            else:
                doc2 = doc
            for vname, v, expect in values:
                p = scen(f"{f}={vname}", _set(doc2, keys, v))
                field = ".".join(f"[{k}]" if isinstance(k, int) else k for k in keys).replace(".[", "[")
                issue = vname in issue_numbers.get(f, ())
                add("numbers", f"{f}: {vname}", ["validate", p], "refuse" if issue else expect, issue, says=[f"field '{field}'"] if issue else ())
    step = scen("robot.step=1e-7", _set(base, ["robot", "step"], 1e-7))
    add("numbers", "robot.step: 1e-7", ["validate", step], issue=True, says=["robot.step"])
    add("numbers", "recording_hours: [25]", ["validate", scen("hours25", _set(office, ["objects", "recording_hours"], [25]))], issue=True,
        says=["objects.recording_hours[0]"])
    add("numbers", "recording_hours: [-1]", ["validate", scen("hours-1", _set(office, ["objects", "recording_hours"], [-1]))], issue=True,
        says=["objects.recording_hours[0]"])
    add("numbers", "timeline hour 30", ["validate", scen("tl30", _set(office, ["objects", "timelines", "Static", "mug"], {30: "A"}))])
    for name, planner in (("nsos alpha nan", {"name": "nsos", "alpha": NAN}), ("bvp window inf", {"name": "bvp", "window": INF}),
                          ("bvp window 1e9", {"name": "bvp", "window": 1e9}), ("nsos w_g inf", {"name": "nsos", "w_g": INF})):
        add("numbers", name, ["validate", scen(name.replace(" ", "_"), _set(base, ["planners"], [planner]))], issue="window" in name,
            says=["planners[0]"])
    lsos = _set(office, ["planners"], [{"name": "lsos", "radius": INF}])
    add("numbers", "lsos radius inf", ["validate", scen("lsos_inf", lsos)], issue=True, says=["planners[0].radius"])
    # extreme but valid: accepted, and a run finishes
    for name, keys, v in (("laser.range 50", ["laser", "range"], 50.0), ("belief.visited_radius 20", ["belief", "visited_radius"], 20.0),
                          ("experiment.max_distance 1e6", ["experiment", "max_distance"], 1e6), ("robot.step 0.01", ["robot", "step"], 0.01)):
        p = scen(name.replace(" ", "_"), _set(_set(base, keys, v), ["goals"], [304]))
        add("numbers", f"run with {name}", ["run", p, "--seeds", "1", "--workers", "1", "--out", root / "out" / name.replace(" ", "_")], "accept")

    # -- files: the scenario file itself
    def raw(name: str, data: bytes) -> Path:
        p = root / "files" / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(data)
        return p

    text = yaml.safe_dump(base, sort_keys=False) + "# caf\u00e9 \u00b0\n"
    for name, data in (("utf16.yaml", text.encode("utf-16")), ("latin1.yaml", text.encode("latin-1")),
                       ("binary.yaml", bytes(range(256)) * 8), ("empty.yaml", b""), ("scalar.yaml", b"42\n"),
                       ("list.yaml", b"- a\n- b\n"), ("syntax.yaml", b"name: [unclosed\nmap: {\n"),
                       ("tag.yaml", b"name: !!python/object/apply:os.system ['echo pwned']\n"),
                       ("nested.yaml", b"[" * 5000 + b"]" * 5000), ("nested_map.yaml", b"a: " + b"{b: " * 3000 + b"1" + b"}" * 3000),
                       ("bomb.yaml", b"a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
                                     b"c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
                                     b"e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]\nf: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]\n"),
                       ("crlf_bom.yaml", b"\xef\xbb\xbf" + text.encode().replace(b"\n", b"\r\n"))):
        expect = "accept" if name == "crlf_bom.yaml" else "refuse"
        add("files", f"scenario {name}", ["validate", raw(name, data)], expect,
            issue=name in ("utf16.yaml", "latin1.yaml", "binary.yaml", "nested.yaml"),
            says={"utf16.yaml": ["UTF-16"], "latin1.yaml": ["UTF-8"], "binary.yaml": ["UTF-8"], "nested.yaml": ["nested"]}.get(name, ()))
    (root / "files" / "folder.yaml").mkdir(parents=True, exist_ok=True)
    for name, path in (("/dev/null", "/dev/null"), ("/dev/zero", "/dev/zero"), ("a folder", root / "files" / "folder.yaml"),
                       ("missing", root / "files" / "missing.yaml")):
        add("files", f"scenario {name}", ["validate", path], issue=name != "missing",
            says=["not found"] if name == "missing" else ["is a folder"] if name == "a folder" else ["not a regular file"])
    # doors files
    dtext = (demo / "doors.csv").read_text()
    doors_cases = [("doors.csv utf16", "csv", dtext.encode("utf-16"), True), ("doors.csv latin1", "csv", (dtext + "999,1,1,\u00e9\n").encode("latin-1"), True),
                   ("doors.csv binary", "csv", bytes(range(256)) * 4, True), ("doors.csv no header", "csv", b"1,2,3\n", False),
                   ("doors.csv nan x", "csv", dtext.encode() + b"999,nan,10,0\n", True), ("doors.csv inf facing", "csv", dtext.encode() + b"999,15,10,inf\n", True),
                   ("doors.csv short row", "csv", dtext.encode() + b"999,15\n", False), ("doors.yaml scalar", "yaml", b"42\n", True),
                   ("doors.yaml syntax", "yaml", b"- {number: 1, x: [\n", True), ("doors.yaml python tag", "yaml", b"- !!python/object/apply:os.system ['echo x']\n", True),
                   ("doors.yaml mapping", "yaml", b"number: 1\n", False), ("doors.yaml list of text", "yaml", b"- a\n- b\n", False),
                   ("doors.yaml utf16", "yaml", "- {number: 1, x: 15, y: 10, facing: 0}\n".encode("utf-16"), True),
                   ("doors.yaml nested", "yaml", b"[" * 5000 + b"]" * 5000, True)]
    for name, ext, data, issue in doors_cases:
        p = raw(name.replace(" ", "_").replace(".", "_") + "." + ext, data)
        add("files", name, ["validate", scen(name.replace(" ", "_"), _set(base, ["doors"], str(p)))], issue=issue,
            says=["UTF-16"] if "utf16" in name else ["finite"] if "nan x" in name or "inf facing" in name else
            ["not valid YAML"] if "syntax" in name or "tag" in name else ["nested"] if "nested" in name else ())
    for name, path in (("doors /dev/zero", "/dev/zero"), ("doors folder", str(root / "files")), ("doors missing", str(root / "nope.csv"))):
        add("files", name, ["validate", scen(name.replace(" ", "_").replace("/", ""), _set(base, ["doors"], path))], issue=name != "doors missing",
            says={"doors /dev/zero": ["not a regular file"], "doors folder": ["is a folder"]}.get(name, ["not found"]))
    # maps
    img = cv2.imread(str(demo / "map.png"), cv2.IMREAD_GRAYSCALE)
    maps = root / "maps"
    maps.mkdir(exist_ok=True)
    cv2.imwrite(str(maps / "black.png"), np.zeros_like(img))
    cv2.imwrite(str(maps / "one.png"), np.full((1, 1), 255, np.uint8))
    cv2.imwrite(str(maps / "dark16.png"), img.astype(np.uint16))  # 8-bit levels in a 16-bit file: all dark
    cv2.imwrite(str(maps / "full16.png"), img.astype(np.uint16) * 257)  # a proper 16-bit map
    cv2.imwrite(str(maps / "rgb.png"), cv2.cvtColor(img, cv2.COLOR_GRAY2BGR))
    cv2.imwrite(str(maps / "inverted.png"), 255 - img)
    _png_header(maps / "huge.png", 100000, 100000)
    (maps / "truncated.png").write_bytes((demo / "map.png").read_bytes()[:200])
    (maps / "text.png").write_text("not an image\n")
    for name, f, expect, issue in (("all-black map", "black.png", "refuse", True), ("1x1 map", "one.png", "refuse", True),
                                   ("16-bit dark map", "dark16.png", "refuse", True), ("16-bit map", "full16.png", "accept", False),
                                   ("RGB map", "rgb.png", "accept", False), ("inverted map", "inverted.png", "refuse", False),
                                   ("PNG header 100000 x 100000", "huge.png", "refuse", True), ("truncated PNG", "truncated.png", "refuse", False),
                                   ("text as PNG", "text.png", "refuse", False), ("map /dev/zero", "/dev/zero", "refuse", True),
                                   ("map folder", str(maps), "refuse", True)):
        path = f if f.startswith("/") else str(maps / f)
        add("files", name, ["validate", scen(name.replace(" ", "_").replace("/", ""), _set(base, ["map", "image"], path))], expect, issue,
            says=[] if expect == "accept" else ["field 'map.image'"] + ({"map /dev/zero": ["not a regular file"], "map folder": ["is a folder"],
                                                                         "PNG header 100000 x 100000": ["100000 x 100000"]}.get(name, [])))
    for name, res in (("resolution 0.01 (map too small for its signs)", 0.01), ("resolution 1.0", 1.0), ("resolution 0", 0), ("resolution 1e-9", 1e-9)):
        p = scen(name.split(" (")[0].replace(" ", "_"), _set(base, ["map", "resolution"], res))
        add("files", f"map {name}", ["validate", p], issue=res in (0.01, 1.0), says=["map.resolution"])
    ros = {"image": str(demo / "map.png"), "resolution": INF, "origin": [0, 0, 0]}
    add("files", "ROS map resolution inf", ["validate", scen("ros_inf", {**{k: v for k, v in base.items() if k != "map"},
                                                                           "map": {"ros": str(_dump(maps / "ros_inf.yaml", ros))}})])
    add("files", "ROS map origin nan", ["validate", scen("ros_nan", {**{k: v for k, v in base.items() if k != "map"},
                                                                        "map": {"ros": str(_dump(maps / "ros_nan.yaml", {**ros, "resolution": 0.1, "origin": [NAN, 0, 0]}))}})])

    # -- structure: wrong types and unknown keys
    for name, keys, v in (("goals a mapping", ["goals"], {"a": 1}), ("planners empty", ["planners"], []), ("planner unknown", ["planners"], [{"name": "nope"}]),
                          ("planners a string", ["planners"], "greedy"), ("start a list", ["start"], [1, 2]), ("unknown key", ["colour"], "red"),
                          ("unknown section key", ["robot", "wheels"], 4), ("name ..", ["name"], ".."), ("name with slash", ["name"], "a/b"),
                          ("name empty", ["name"], ""), ("goal not a sign", ["goals"], [99999]), ("duplicates bogus", ["duplicates"], "sometimes"),
                          ("kind bogus", ["kind"], "cats"), ("map both sources", ["map", "ros"], "x.yaml"), ("start in a wall", ["start"], {"x": 0.5, "y": 0.5}),
                          ("beams 1e6", ["laser", "beams"], 10**6), ("seeds 1e9", ["experiment", "seeds"], 10**9)):
        add("structure", name, ["validate", scen("s_" + name.replace(" ", "_"), _set(base, keys, v))], issue=name == "name ..",
            says=["field '" + ".".join(map(str, keys)) + "'"] if keys[0] in ("name", "robot", "laser", "experiment") else ())

    # -- output folders and files
    afile = root / "a_file.txt"
    afile.write_text("x")
    for name, out in (("--out a file", afile), ("--out under a file", afile / "sub"), ("--out in /proc", "/proc/semsearch"),
                      ("--out in /sys", "/sys/semsearch"), ('--out ""', "")):
        add("output", f"run {name}", ["run", good, "--seeds", "1", "--out", out], issue=True, says=["--out"])
    add("output", 'name: ".." writes into the working folder', ["run", scen("dotdot", _set(base, ["name"], "..")), "--seeds", "1"], issue=True)
    for name, out in (("show --out .xyz", root / "m.xyz"), ("show --out no extension", root / "m"), ("show --out a folder", root),
                      ("show --out under a file", afile / "m.png"), ('show --out ""', "")):
        add("output", name, ["show", good, "--out", out], issue=name == "show --out .xyz", says=["--out"])
    add("output", "show --out .svg", ["show", good, "--out", root / "m.svg"], "accept")
    add("output", "report --out a file", ["report", root / "nofolder", "--out", afile])
    add("output", "record --out a file", ["record", good, "--out", afile])
    add("output", "generate building --out a file", ["generate", "building", "--layout", "grid", "--numbering", "normal", "--out", afile])
    add("output", "generate rooms --out under a file", ["generate", "rooms", "--out", afile / "x"])
    add("output", "import ros --out a file", ["import", "ros", root / "maps" / "ros_inf.yaml", demo / "doors.csv", "--out", afile])
    # results files: runs.csv and meta.json damaged
    for name, runs, meta in (("runs.csv binary garbage", bytes(range(256)) * 16, None), ("runs.csv wrong columns", b"a,b,c\n1,2,3\n", None),
                             ("runs.csv empty", b"", None), ("meta.json garbage", None, b"{not json"), ("meta.json binary", None, bytes(range(256))),
                             ("meta.json a list", None, b"[1, 2]")):
        folder = root / "results" / name.replace(" ", "_")
        folder.mkdir(parents=True, exist_ok=True)
        if runs is not None:
            (folder / "runs.csv").write_bytes(runs)
        if meta is not None:
            (folder / "meta.json").write_bytes(meta)
        issue = name in ("runs.csv binary garbage", "runs.csv wrong columns", "meta.json garbage")
        add("output", f"run into {name}", ["run", good, "--seeds", "1", "--out", folder], "either" if name == "runs.csv empty" else "refuse", issue,
            says=[] if name == "runs.csv empty" else [name.split()[0]])
        if runs is not None:
            shutil.copytree(folder, folder.with_name(folder.name + "_report"))
            add("output", f"report of {name}", ["report", folder.with_name(folder.name + "_report"), "--no-replay"], issue=issue,
                says=["runs.csv"])

    # -- user text read as console markup
    add("markup", "planner named [/x]", ["validate", scen("mk_planner", _set(base, ["planners"], [{"name": "[/x]"}]))], issue=True,
        says=["'[/x]'"])
    add("markup", "scenario file [/a].yaml", ["validate", _dump(root / "[" / "a].yaml", base)], "accept", issue=True, says=["[/a].yaml: ok"])
    add("markup", "map path with brackets", ["validate", scen("mk_map", _set(base, ["map", "image"], str(root / "[bold]" / "[/x]map.png")))], issue=True,
        says=["[bold]/[/x]map.png"])
    add("markup", "goal [bold]", ["run", good, "--goal", "[bold]", "--out", root / "out" / "mk"], issue=True, says=["goal [bold]"])

    # -- the command line
    for name, args, issue in (('--goal ""', ["run", good, "--goal", "", "--out", root / "out" / "g"], True),
                              ("--goal ,", ["run", good, "--goal", ",", "--out", root / "out" / "g"], False),
                              ('--planner ""', ["run", good, "--planner", "", "--out", root / "out" / "g"], False),
                              ("--planner unknown", ["run", good, "--planner", "nope", "--out", root / "out" / "g"], False),
                              ("--seeds 0", ["run", good, "--seeds", "0"], False), ("--seeds 1000000000", ["run", good, "--seeds", "1000000000", "--out", root / "out" / "s"], True),
                              ("--seeds abc", ["run", good, "--seeds", "abc"], False), ("--workers 0", ["run", good, "--workers", "0"], False),
                              ("--workers 100000", ["run", good, "--workers", "100000", "--out", root / "out" / "w"], True),
                              ("--alphas nan", ["sweep-alpha", good, "--alphas", "nan"], False), ("--alphas 2", ["sweep-alpha", good, "--alphas", "2"], False),
                              ("--param no =", ["sweep", good, "--param", "robot.step"], False),
                              ("--param nan value", ["sweep", good, "--param", "robot.step=nan", "--out", root / "out" / "p"], False),
                              ("--param unknown section", ["sweep", good, "--param", "wheels.n=1,2", "--out", root / "out" / "p"], False),
                              ("--format xyz", ["report", root / "results", "--format", "xyz"], False),
                              ("report of a folder without runs.csv", ["report", root / "maps"], False),
                              ("presence --hours nan", ["presence", REPO / "configs" / "hh106_counts.csv", "--hours", "nan"], False),
                              ("presence counts /dev/zero", ["presence", "/dev/zero", "--hours", "1"], False),
                              ("generate rooms --size nan", ["generate", "rooms", "--out", root / "out" / "r", "--size", "nan,6"], False),
                              ("generate building --spacing inf", ["generate", "building", "--layout", "grid", "--numbering", "normal",
                                                                   "--out", root / "out" / "b", "--spacing", "inf"], False),
                              ("import mobilesim --start nan", ["import", "mobilesim", root / "a_file.txt", root / "a_file.txt", "--out", root / "out" / "m",
                                                                "--start", "nan,1"], False)):
        add("command line", name, args, issue=issue, says=[name.split()[0]] if name.startswith("--") else ())

    # -- resources
    sweep = _set(base, ["planners"], [{"name": "nsos", "alpha": [round(0.1 * k, 1) for k in range(6)], "w_g": list(range(1, 7)),
                                       "w_p": list(range(1, 7)), "door_bins": list(range(1, 7)), "robot_bins": list(range(1, 7)),
                                       "hysteresis": [0.0, 0.01, 0.02, 0.03, 0.04, 0.05]}])
    add("resources", "a 46,656-variant planner sweep validates", ["validate", scen("sweep46656", sweep)], "accept", issue=True,
        says=["46656 variants"])
    big = np.full((2000, 2000), 160, np.uint8)
    big[900:1100, 100:1900] = 255
    big[899, 100:1900] = big[1100, 100:1900] = 0
    cv2.imwrite(str(maps / "big.png"), big)
    bigdoc = _set(_set(_set(base, ["map", "image"], str(maps / "big.png")), ["start"], {"x": 20.0, "y": 100.0, "heading": 0}),
                  ["doors"], [{"number": 1, "x": 150.0, "y": 110.05, "facing": -90}, {"number": 2, "x": 180.0, "y": 89.95, "facing": 90}])
    add("resources", "a 2000 x 2000 map validates", ["validate", scen("big2000", _set(bigdoc, ["goals"], [1, 2]))], "accept")

    # -- other commands, importers, planners, paths (process faults: tests/test_faults.py)
    counts = root / "counts"
    counts.mkdir(exist_ok=True)
    for name, text in (("negative", "hour,A\n1,-2\n"), ("infinite", "hour,A\n1,inf\n"), ("header only", "hour,A\n"),
                       ("ragged", "hour,A,B\n1,2\n")):
        f = counts / f"{name.replace(' ', '_')}.csv"
        f.write_text(text)
        add("commands", f"presence counts {name}", ["presence", f, "--hours", "1"], issue=True, says=[str(f.name)])
    add("commands", "presence --out a folder", ["presence", REPO / "configs" / "hh106_counts.csv", "--hours", "1", "--out", root],
        issue=True, says=["--out"])
    add("commands", "generate --seed -5", ["generate", "building", "--layout", "grid", "--numbering", "normal", "--seed", "-5",
                                           "--out", root / "out" / "b"], issue=True, says=["--seed"])
    add("commands", "generate --goals abc", ["generate", "building", "--layout", "grid", "--numbering", "normal", "--goals", "abc",
                                             "--out", root / "out" / "b"], issue=True, says=["--goals"])
    add("commands", "generate batch --seeds 1000000", ["generate", "batch", "--seeds", "1000000", "--out", root / "out" / "gb"],
        issue=True, says=["--seeds"])
    add("commands", "sweep true as a number", ["sweep", good, "--param", "door_camera.p_misread=true", "--out", root / "out" / "t"],
        issue=True, says=["--param"])
    add("commands", "show --out into /proc", ["show", good, "--out", "/proc/semsearch.png"], issue=True, says=["--out"])
    add("commands", "indirect rooms of 25 million cells", ["validate", scen("ind_big", _set(_set(indirect, ["indirect", "rooms", "size"],
                                                                                          [50, 50]), ["indirect", "resolution"], 0.01))],
        issue=True, says=["indirect.resolution"])
    add("commands", "an empty alpha list", ["validate", scen("alpha_empty", _set(base, ["planners"], [{"name": "nsos", "alpha": []}]))],
        issue=True, says=["alpha"])
    ros = root / "ros26"
    ros.mkdir(exist_ok=True)
    cv2.imwrite(str(ros / "m.pgm"), np.where(cv2.imread(str(demo / "map.png"), cv2.IMREAD_GRAYSCALE) >= 200, 254, 0).astype(np.uint8))
    for name, line, key in (("occupied_thresh 1.5", "occupied_thresh: 1.5", "occupied_thresh"),
                            ("free above occupied", "free_thresh: 0.9", "free_thresh"), ("negate yes", "negate: 'yes'", "negate"),
                            ("occupied_thresh abc", "occupied_thresh: abc", "occupied_thresh")):
        f = ros / f"{key}_{len(cases)}.yaml"
        f.write_text(f"image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n{line}\n")
        add("importers", f"import ros {name}", ["import", "ros", f, demo / "doors.csv", "--out", root / "out" / "r"], issue=True,
            says=[key])
    f = ros / "origin_text.yaml"
    f.write_text("image: m.pgm\nresolution: 0.1\norigin: '100'\n")
    add("importers", "import ros origin as text", ["import", "ros", f, demo / "doors.csv", "--out", root / "out" / "r"], issue=True,
        says=["origin"])
    f = ros / "ok.yaml"
    f.write_text("image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n")
    add("importers", "import ros, a goal that is no sign", ["import", "ros", f, demo / "doors.csv", "--out", root / "out" / "r",
                                                            "--goals", "12345"], issue=True, says=["would not validate"])
    kth = ('<floor><Scale PixelDistance="{p}" RealDistance="1"/><space name="B_C" type="KORRIDOR"><contour>'
           '<linesegment {a} y1="0" x2="1000" y2="0" type="Wall"/><linesegment x1="1000" y1="0" x2="1000" y2="200" type="Wall"/>'
           '<linesegment x1="1000" y1="200" x2="0" y2="200" type="Wall"/><linesegment x1="0" y1="200" x2="0" y2="0" type="Wall"/>'
           '</contour></space><space name="B_1" type="KONTOR"><contour><linesegment x1="300" y1="-20" x2="400" y2="-20" '
           'type="Portal" target="B_C"/></contour></space></floor>')
    for name, p, a, says in (("PixelDistance 0", "0", 'x1="0"', "PixelDistance"), ("a missing x1", "100", "", "x1"),
                             ("a coordinate of 1e12", "100", 'x1="1e12"', "from the origin")):
        f = root / f"kth_{len(cases)}.xml"
        f.write_text(kth.format(p=p, a=a))
        add("importers", f"import kth {name}", ["import", "kth", f, "--out", root / "out" / "k"], issue=True, says=[says])
    planner = root / "exits_at_import.py"
    planner.write_text("import sys\nsys.exit(3)\n")
    add("planners", "a planner file that exits at import",
        ["validate", scen("exits", _set(base, ["planners"], [{"name": "x", "module": str(planner)}]))], issue=True,
        says=["exits_at_import.py"])
    shutil.rmtree(root / "out", ignore_errors=True)
    return cases
