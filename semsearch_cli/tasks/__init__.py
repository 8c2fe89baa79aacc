"""Tasks: one module per kind of search over the shared core, behind one protocol
(:class:`~semsearch_cli.tasks.base.Task`), driven by one step loop (:mod:`.loop`).
Importing this package registers every kind."""

from . import chain, doors, indirect, objects  # noqa: F401  (registration side effect)
from .base import (TASKS, Event, FrameRecorder, Observer, Observers, OpenEpisode, Outcome, RobotState, RunResult, StageObserver, OnMapTask, Task, TraceObserver, build_task,
                   register_task)
from .episodes import Episode, episode_seed

__all__ = ["TASKS", "Event", "FrameRecorder", "Observer", "Observers", "OnMapTask", "OpenEpisode", "Outcome", "StageObserver", "TraceObserver", "RobotState", "RunResult", "Task", "build_task", "register_task", "Episode", "episode_seed"]
