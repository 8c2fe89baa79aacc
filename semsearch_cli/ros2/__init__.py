"""From the simulator to ROS 2: runs exported as bags (``semsearch export``), door planners
replayed over them (``semsearch ros replay``) and exploring with a robot through rosbridge
(``semsearch ros live``), without a ROS install (the ``ros`` extra: rosbags, mcap, roslibpy,
websockets). See docs/robot.md."""

from ..optional import installed
from .bag import FORMATS, TOPICS
from .export import BagRecorder, Exported, export_folder, export_run, exportable, recorded_runs
from .folder import check_run, is_live_folder, read_run, verify_live, write_live_folder
from .live import Live, LiveRun
from .loopback import Rosbridge, SimRobot
from .replay import Replayed, recorded_scenario, replay_bag
from .robot import MAX_MARGIN


def available(*packages: str) -> bool:
    """Whether the ros extra's ``packages`` are installed (default: rosbags, which writes and reads
    the bags and their messages); ``ros live`` also needs roslibpy (rosbridge's client), ``ros sim``
    websockets (the stand-in robot's server)."""
    return all(installed(name) for name in (packages or ("rosbags",)))


__all__ = ["FORMATS", "MAX_MARGIN", "TOPICS", "BagRecorder", "Exported", "Live", "LiveRun", "Replayed", "Rosbridge", "SimRobot", "available", "export_folder", "export_run", "exportable",
           "check_run", "is_live_folder", "read_run", "recorded_runs", "recorded_scenario", "replay_bag", "verify_live", "write_live_folder"]
