"""The commands as Python functions, one module per feature (runs, reports, verify, ros, info,
make, suites, llm); the CLI only parses, calls these and prints. Every name is importable from here, as
before the split."""

from ..errors import MissingExtra, ScenarioError
from .runs import (RunOutput, default_out, RECORDED, run, first_prompt, sweep_alpha, SweepOutput, parse_param, sweep,
    write_summary, record)
from .reports import report, presence
from .verify import VerifyOutput, verify
from .ros import export, ros_replay, ros_live, ros_sim
from .info import schema_text, schema, validate, show, episodes, planners, scenarios, init, planner_spec
from .make import (imported, LAYOUTS, SCHEMES, KTH_CORRIDOR_TYPES, generate_building, generate_batch, generate_rooms,
    import_mobilesim, import_ros, import_kth)
from .suites import bench_run, bench_list, bench_board, bench_fetch, bench_hash
from .llm import llm_serve, model_identity

__all__ = [
    "MissingExtra", "ScenarioError", "RunOutput", "default_out", "RECORDED", "run", "first_prompt",
    "sweep_alpha", "SweepOutput", "parse_param", "sweep", "write_summary", "record", "report", "presence",
    "VerifyOutput", "verify", "export", "ros_replay", "ros_live", "ros_sim", "schema_text", "schema",
    "validate", "show", "episodes", "planners", "scenarios", "init", "planner_spec", "imported", "LAYOUTS",
    "SCHEMES", "KTH_CORRIDOR_TYPES", "generate_building", "generate_batch", "generate_rooms",
    "import_mobilesim", "import_ros", "import_kth", "bench_run", "bench_list", "bench_board", "bench_fetch",
    "bench_hash", "llm_serve", "model_identity"
]
