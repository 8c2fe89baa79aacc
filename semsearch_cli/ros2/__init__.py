"""From the simulator to ROS 2: runs exported as bags (``semsearch export``), door planners
replayed over them (``semsearch ros replay``) and exploring with a robot through rosbridge
(``semsearch ros live``), without a ROS install (the ``ros`` extra: rosbags, mcap, roslibpy,
websockets). See docs/robot.md."""

from ..optional import installed
from .bag import FORMATS, TOPICS
from .export import BagRecorder, Exported, export_folder, export_run, exportable, recorded_runs
from .live import Live, LiveRun
from .loopback import Rosbridge, SimRobot
from .replay import Replayed, recorded_scenario, replay_bag


def available() -> bool:
    """Whether the ros extra is installed (rosbags writes the bags; roslibpy speaks to rosbridge;
    websockets serves the stand-in robot)."""
    return all(installed(name) for name in ("rosbags", "roslibpy", "websockets"))


__all__ = ["FORMATS", "TOPICS", "BagRecorder", "Exported", "Live", "LiveRun", "Replayed", "Rosbridge", "SimRobot", "available", "export_folder", "export_run", "exportable",
           "recorded_runs", "recorded_scenario", "replay_bag"]
