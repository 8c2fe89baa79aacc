"""``semsearch ros replay``, ``ros live`` and ``ros sim``: door planners over bags and on robots (the
ros extra)."""

from __future__ import annotations

import shlex
import time
from pathlib import Path
from typing import Optional

import typer

from .. import api
from ..errors import ScenarioError
from .common import SCENARIO, _fail, _path, app, err, out


ros_app = typer.Typer(no_args_is_help=True, help="Door planners over ROS 2 bags and on robots through rosbridge (the ros extra; "
                      "docs/robot.md).")
app.add_typer(ros_app, name="ros")


@ros_app.command("replay")
def ros_replay(
    bag: Path = typer.Argument(..., help="A ROS 2 bag folder: one `semsearch export` wrote, or a robot's own (/map, a pose, "
                               "/semsearch/detections; give --goal)."),
    planner: str = typer.Option(..., "--planner", help="The door planner to ask: NAME or NAME\\[key=value,...], e.g. nsos\\[alpha=0.9]."),
    out_dir: str = typer.Option(..., "--out", callback=_path, help="The new bag folder for its decisions (must not exist)."),
    scenario: Optional[Path] = typer.Option(None, "--scenario", help="The scenario the bag was recorded on (default: the "
                                            "shipped scenario the bag names); for a robot's bag, where its settings come from."),
    fmt: str = typer.Option("mcap", "--format", help="mcap or rosbag2 (SQLite 3), for the new bag."),
    planner_file: Optional[Path] = typer.Option(None, "--planner-file", help="A Python file that registers the planner."),
    goal: Optional[str] = typer.Option(None, "--goal", help="The label to find, for a robot's own bag (a bag of `semsearch "
                                       "export` names its goal)."),
    margin: float = typer.Option(10.0, "--margin", help="For a robot's own bag: metres of grid around its first map (as "
                                 "`ros live --margin`)."),
):
    """Ask a door planner where it would go at each re-plan of a bag.

    The robot moves as it moved; the planner's answers (/semsearch/goal, /explore/frontiers, /semsearch/decision) to a new
    bag. Over a bag of `semsearch export`, the run's own planner makes the run's decisions, decision
    for decision; a robot's own bag (/map, a pose, /semsearch/detections) needs --goal."""

    try:
        res = api.ros_replay(bag, planner, out_dir, scenario, fmt, planner_file, goal, margin)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"{res.folder}: {len(res.decisions)} decisions of {planner} over {bag} "
              f"({'the goal was read in the bag' if res.found else 'the goal was never read in the bag'})")
    if res.dropped:
        out.print(f"not taken from the bag: {res.dropped}")


@ros_app.command("live")
def ros_live(
    rosbridge: str = typer.Option(..., "--rosbridge", help="The robot's rosbridge_server: ws://HOST:PORT (it listens on 9090)."),
    planner: str = typer.Option(..., "--planner", help="The door planner: NAME or NAME\\[key=value,...], e.g. nsos\\[alpha=0.9]."),
    goal: str = typer.Option(..., "--goal", help="The label to find (a door's number)."),
    scenario: Optional[Path] = typer.Option(None, "--scenario", help="Where the belief's, robot's and navigation's settings "
                                            "come from, and the distance budget (default: their defaults, no budget)."),
    publish_only: bool = typer.Option(False, "--publish-only", help="Drive nothing: publish each goal on /semsearch/goal "
                                      "(PoseStamped) instead of sending Nav2 NavigateToPose goals."),
    out_dir: Optional[str] = typer.Option(None, "--out", callback=_path, help="The run's folder: the bag of the messages it "
                                          "took, its decisions record (semsearch verify checks it), its planner's transcript "
                                          "and run.json (default: live-DATE-TIME)."),
    repro: Optional[str] = typer.Option(None, "--repro", callback=_path, help="Deprecated since 0.4.0 (use --out): without "
                                        "--out, only a run that does not find the goal leaves its bag, here."),
    margin: float = typer.Option(10.0, "--margin", help="Metres of grid around the robot's first map, for the map to grow into."),
    max_distance: Optional[float] = typer.Option(None, "--max-distance", help="Stop after this many metres (default: the "
                                                 "scenario's experiment.max_distance, else none)."),
    planner_file: Optional[Path] = typer.Option(None, "--planner-file", help="A Python file that registers the planner."),
    silence: float = typer.Option(30.0, "--silence", help="Give up when the robot has sent nothing for this many seconds."),
):
    """Explore with a robot through rosbridge until the goal's sign is read.

    In the place of explore_lite: the robot's /map, pose and /semsearch/detections in; /explore/frontiers,
    /semsearch/goal and Nav2 NavigateToPose goals out; /explore/resume pauses and resumes. A run
    that does not find the goal leaves a repro bag for `semsearch ros replay`. Exit status 0 when
    the goal was found, 1 otherwise."""

    try:
        res = api.ros_live(rosbridge, planner, goal, scenario, publish_only, repro, margin, max_distance, planner_file,
                           silence, log=lambda text: err.print(text), out=out_dir)
    except ScenarioError as exc:
        _fail(exc)
    n = len(res.decisions)
    sent = "targets published on /semsearch/goal" if publish_only else f"{res.goals} goals sent to Nav2 (one a re-plan)"
    out.print(f"{res.outcome}: {res.message}; {res.distance:.1f} m along {res.poses} poses, {n} decision{'s' * (n != 1)}, "
              f"{sent}")
    if res.costs:
        out.print("planner's costs: " + ", ".join(f"{k} {v:g}" for k, v in res.costs.items()), highlight=False)
    if res.dropped:
        out.print(f"not taken from the robot: {res.dropped}")
    if res.bag is not None:
        folder = res.bag.parent
        out.print(f"run folder: {folder} (bag, decisions record{', transcript' if res.transcripts else ''}, run.json; "
                  f"check it: semsearch verify {shlex.quote(str(folder))})", highlight=False, soft_wrap=True)
    if res.repro is not None:
        size = sum(p.stat().st_size for p in res.repro.rglob("*") if p.is_file())
        if res.poses == 0:
            out.print(f"repro bag: {res.repro} ({size / 1e6:.2f} MB; no pose came, so there is nothing to replay)")
        else:
            again = f" --margin {margin:g}" + (f" --scenario {shlex.quote(str(scenario))}" if scenario is not None else "")
            out.print(f"repro bag: {res.repro} ({size / 1e6:.2f} MB; replay it: semsearch ros replay {shlex.quote(str(res.repro))}"
                      f" --goal {shlex.quote(goal)} --planner {shlex.quote(planner)}{again} --out "
                      f"{shlex.quote(str(res.repro) + '-replayed')})")
    raise typer.Exit(0 if res.outcome == "found" else 1)


@ros_app.command("sim")
def ros_sim(
    scenario: Path = SCENARIO,
    goal: str = typer.Option(..., "--goal", help="The goal whose first episode the robot starts from (its start, its seed)."),
    seed: int = typer.Option(0, "--seed", min=0, help="The repeat (the generator `semsearch run` gives that episode and seed)."),
    port: int = typer.Option(9090, "--port", min=0, max=65535, help="The port on 127.0.0.1 (rosbridge_server's is 9090)."),
    period: float = typer.Option(0.2, "--period", help="Seconds between the robot's steps."),
    follow: Optional[str] = typer.Option(None, "--follow", help="Also drive to each PoseStamped published on this topic (for "
                                         "`ros live --publish-only`: /semsearch/goal)."),
):
    """A robot without ROS, to try `semsearch ros live` on.

    The scenario's simulated robot (one episode: the goal's first, and one seed) behind a rosbridge
    server on 127.0.0.1, publishing /map, /semsearch/pose and /semsearch/detections and taking Nav2
    NavigateToPose goals on /navigate_to_pose. Runs until Ctrl-C; start it again for another run."""

    try:
        bot = api.ros_sim(scenario, goal, seed, port, period, follow)
    except ScenarioError as exc:
        _fail(exc)
    out.print(f"rosbridge on {bot.bridge.url}: the robot of {scenario} at ({bot.st.x:g}, {bot.st.y:g}), waiting for goals "
              "(Ctrl-C stops it)")
    told = False

    def tell():  # once, when the robot's cameras have read the goal's sign
        nonlocal told
        if bot.found_at is not None and not told:
            told = True
            out.print(f"read the sign {goal} after {bot.found_at:.2f} m, {len(bot.goals)} goals so far")
    try:
        while True:
            time.sleep(0.2)
            tell()
    except KeyboardInterrupt:
        pass
    finally:  # Ctrl-C, or SIGTERM (which goes on to exit 143)
        bot.bridge.stop()
        tell()
        out.print(f"stopped after {bot.distance:.2f} m, {bot.st.steps} steps, {len(bot.goals)} goals")
