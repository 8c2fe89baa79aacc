"""From the simulator to ROS 2: runs exported as bags (``semsearch export``) and door planners
replayed over them (``semsearch ros replay``), without a ROS install (the ``ros`` extra: rosbags,
mcap). See docs/robot.md."""

import importlib.util

from .bag import FORMATS, TOPICS
from .export import BagRecorder, Exported, export_folder, export_run, recorded_runs
from .replay import Replayed, recorded_scenario, replay_bag


def available() -> bool:
    """Whether the ros extra is installed (rosbags writes the bags)."""
    return importlib.util.find_spec("rosbags") is not None


__all__ = ["FORMATS", "TOPICS", "BagRecorder", "Exported", "Replayed", "available", "export_folder", "export_run",
           "recorded_runs", "recorded_scenario", "replay_bag"]
