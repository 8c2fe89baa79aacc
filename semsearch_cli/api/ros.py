"""The robot bridge's commands (the ros extra): ``export`` (runs as bags), ``ros_replay``, ``ros_live``
and ``ros_sim``."""

from __future__ import annotations

import math
import time
from pathlib import Path

from ..config.base import sign_label
from ..deprecation import warn
from ..errors import MissingExtra, ScenarioError, did_you_mean
from ..planners import expand_variants
from ..runner import Loaded, folder_lock
from ..runner.verify import check_folder_engine
from ..tasks import TASKS
from ..tasks.doors import DoorTask
from .. import ros2, shipped
from ..shipped import scenario_file
from .verify import rows_scenario
from .info import planner_spec


def export(folder: str | Path, out: str | Path, fmt: str = "mcap", run: str | None = None,
           scenario: str | Path | None = None, kept=None) -> list:
    """Every door-search run of a results folder recorded with ``--decisions`` (or the one named
    ``run``, its record's file stem) as a ROS 2 bag folder ``out/<run>`` (``fmt``: ``mcap`` or
    ``rosbag2``, SQLite 3), replayed from its decisions (:mod:`semsearch_cli.ros2`; the ``ros``
    extra). Runs whose bag exists already are kept (``kept``, when given, is called with each one's
    name). Returns the :class:`~semsearch_cli.ros2.Exported` runs."""
    if fmt not in ros2.FORMATS:
        raise ScenarioError("<command line>", "--format", f"{fmt!r} is not a bag format; use one of {', '.join(ros2.FORMATS)}")
    if not ros2.available():
        raise MissingExtra("semsearch export", "ros")
    folder = Path(folder)
    check_folder_engine(folder)
    _, loaded = rows_scenario(folder, scenario)
    ros2.exportable(loaded)  # before the output folder is made
    with folder_lock(Path(out)):
        return ros2.export_folder(loaded, folder, Path(out), fmt, run, kept)


def ros_replay(bag: str | Path, planner: str, out: str | Path, scenario: str | Path | None = None, fmt: str = "mcap",
               planner_file: str | Path | None = None, goal: str | None = None, margin: float = 10.0):
    """Run a door planner (``NAME`` or ``NAME[key=value,...]``) over a bag, asked at each of its
    re-plans, and write its decisions as a new bag folder ``out``
    (:func:`~semsearch_cli.ros2.replay_bag`; the ``ros`` extra). A bag ``semsearch export`` wrote
    replays on ``scenario``, the one it was recorded on (default: the shipped scenario the bag
    names); a robot's own bag (a map, a pose, the detections) needs ``goal``, the label to find,
    takes its settings from ``scenario`` when given, and is folded into its first map and ``margin``
    metres around it (as :func:`ros_live` folds a robot's maps). Returns the
    :class:`~semsearch_cli.ros2.Replayed`."""
    _margin(margin)
    goal = _label(goal) if goal is not None else None
    if fmt not in ros2.FORMATS:
        raise ScenarioError("<command line>", "--format", f"{fmt!r} is not a bag format; use one of {', '.join(ros2.FORMATS)}")
    if not ros2.available():
        raise MissingExtra("semsearch ros replay", "ros")
    bag = Path(bag)
    if bag.is_file():
        raise ScenarioError(str(bag), "", f"is a file: give the bag's folder, {bag.parent} (a ROS 2 bag is a folder with "
                            "metadata.yaml)")
    if not bag.is_dir():
        raise ScenarioError(str(bag), "", "no such bag folder (a ROS 2 bag is a folder with metadata.yaml)")
    name = ros2.recorded_scenario(bag)  # None: a robot's own bag
    if scenario is None and name is not None:
        if name not in shipped.names():
            raise ScenarioError(str(bag), "/semsearch/setup", f"names the scenario {name!r}, which is not a shipped one: give "
                                "the scenario the bag was recorded on, --scenario FILE")
        scenario = name
    loaded = Loaded.load(scenario_file(scenario), planners=False) if scenario is not None else None
    return ros2.replay_bag(loaded, bag, _door_variant(planner, planner_file), Path(out), fmt, goal, margin)


def ros_live(rosbridge: str, planner: str, goal: str, scenario: str | Path | None = None, publish_only: bool = False,
             repro: str | Path | None = None, margin: float = 10.0, max_distance: float | None = None,
             planner_file: str | Path | None = None, silence: float = 30.0, log=None, out: str | Path | None = None):
    """Explore with a robot through rosbridge (``ws://HOST:PORT``) until the sign ``goal`` is
    read, door planner ``planner`` choosing where to go (:mod:`semsearch_cli.ros2.live`; the
    ``ros`` extra): the robot's /map, pose and /semsearch/detections in; /explore/frontiers,
    /semsearch/goal and Nav2 ``NavigateToPose`` goals out (none with ``publish_only``). The
    belief's, robot's and navigation's settings come from ``scenario`` when given, and its
    ``experiment.max_distance`` unless ``max_distance`` is; ``margin`` metres of grid surround the
    robot's first map. The planner is seated as in a batch, and the run's folder ``out`` (default
    ``live-DATE-TIME``) gets its bag, decisions record, transcript and ``run.json``
    (:mod:`semsearch_cli.ros2.folder`), which ``semsearch verify`` checks. ``repro`` (deprecated
    since 0.4.0): with no ``out``, only a failed run's bag, there, as before 0.4.0. ``log`` takes a
    line of progress. Returns the :class:`~semsearch_cli.ros2.LiveRun`."""
    if not ros2.available("rosbags", "roslibpy"):  # rosbags: the repro bag
        raise MissingExtra("semsearch ros live", "ros")
    _margin(margin)
    if max_distance is not None and not max_distance > 0:
        raise ScenarioError("<command line>", "--max-distance", f"{max_distance:g} m: give more than 0")
    if not 0 < silence < math.inf:
        raise ScenarioError("<command line>", "--silence", f"{silence:g} s: give a number of seconds over 0")
    goal = _label(goal)
    loaded = Loaded.load(scenario_file(scenario), planners=False) if scenario is not None else None
    if loaded is not None and not isinstance(loaded.task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {loaded.task.kind}: a robot explores with door planners only")
    if max_distance is None and loaded is not None:
        max_distance = loaded.sc.experiment.max_distance
    if repro is not None:
        warn("ros live --repro (a failed run's bag alone)", "give --out DIR: a folder with every run's bag, its decisions "
             "record (semsearch verify DIR checks it) and its planner's transcript", since="0.4.0", until="0.5.0")
    elif out is None:
        out = f"live-{time.strftime('%Y%m%d-%H%M%S')}"
    variant = _door_variant(planner, planner_file)
    live = ros2.Live(rosbridge, variant, goal, loaded.sc if loaded is not None else None,
                     publish_only, repro, margin, max_distance, silence, log, out=out)
    res = live.run()
    if out is not None:
        ros2.write_live_folder(Path(out), res, planner=variant.label, goal=goal,
                               scenario=loaded.path.resolve() if loaded is not None else None,
                               fingerprint=loaded.fingerprint if loaded is not None else None, margin=margin,
                               max_distance=None if max_distance is None or math.isinf(max_distance) else max_distance,
                               publish_only=publish_only)
    return res


def ros_sim(scenario: str | Path, goal: str, seed: int = 0, port: int = 9090, period: float = 0.2,
            follow: str | None = None):
    """A robot without ROS to try :func:`ros_live` on: the simulator's robot of ``scenario``
    (goal ``goal``'s first episode, repeat ``seed``) behind a rosbridge server on
    ``ws://127.0.0.1:port`` (:mod:`semsearch_cli.ros2.loopback`), a step every ``period`` seconds
    (0.2: a step of 0.1 m at 0.5 m/s); with ``follow``, it also drives to each PoseStamped a
    client publishes on that topic (``--publish-only``'s goals). Returns the started
    :class:`~semsearch_cli.ros2.loopback.SimRobot`; ``robot.bridge.stop()`` ends it."""
    if not ros2.available("rosbags", "websockets"):  # rosbags: its messages
        raise MissingExtra("semsearch ros sim", "ros")
    if not 0 < period < math.inf:
        raise ScenarioError("<command line>", "--period", f"{period:g} s: give a number of seconds over 0")
    if follow is not None and not follow.startswith("/"):
        raise ScenarioError("<command line>", "--follow", f"{follow!r}: give a topic's absolute name, e.g. /semsearch/goal")
    loaded = Loaded.load(scenario_file(scenario), planners=False)
    if not isinstance(loaded.task, DoorTask):
        raise ScenarioError(str(loaded.path), "kind", f"is {loaded.task.kind}: the stand-in robot searches for door signs")
    goal = _label(goal)
    if loaded.world.signs.index_of(goal) < 0:
        goals = ", ".join(str(g) for g in loaded.goals)
        raise ScenarioError(str(loaded.path), "--goal", f"no door sign carries {goal!r} in this scenario"
                            f"{did_you_mean(goal, [str(n) for n in loaded.world.signs.number])}; its goals: {goals} "
                            f"(any of its {len(loaded.world.signs.number)} signs may be one)")
    bridge = ros2.Rosbridge(port=port)
    try:
        bridge.start()
    except OSError as exc:
        raise ScenarioError("<command line>", "--port", f"{port}: {exc.strerror or exc}") from None
    return ros2.SimRobot(bridge, loaded, goal, seed, period=period, follow=follow).start()


def _margin(margin: float) -> None:
    if not 0 <= margin <= ros2.MAX_MARGIN:
        raise ScenarioError("<command line>", "--margin", f"{margin:g} m: give 0 to {ros2.MAX_MARGIN:g} metres of grid around "
                            "the first map")


def _label(goal) -> str | int:
    """A goal's label as signs carry it (a whole number is a number), or a ScenarioError."""
    try:
        return sign_label(goal)
    except ValueError as exc:
        raise ScenarioError("<command line>", "--goal", f"{goal!r}: {exc}") from None


def _door_variant(planner: str, planner_file: str | Path | None):
    """The one door-planner variant ``planner`` (NAME or NAME[key=value,...]) names."""
    variants = expand_variants([planner_spec(planner, planner_file)], "<command line>", TASKS["doors"].planner_kind)
    if len(variants) != 1:
        raise ScenarioError("<command line>", "--planner", f"{planner!r} names {len(variants)} variants: give one value per "
                            "parameter")
    return variants[0]
