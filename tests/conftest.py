from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

from semsearch_cli.report.figures import common  # noqa: E402

SHARED = Path(__file__).resolve().parents[2] / "shared"
REF = SHARED / "reference_maps"


@pytest.fixture(scope="session")
def demo_dir(tmp_path_factory):
    from semsearch_cli.world.buildings.demo import write_demo

    d = tmp_path_factory.mktemp("demo")
    write_demo(d)
    return d


@pytest.fixture(scope="session")
def demo_loaded(demo_dir):
    from semsearch_cli.runner import Loaded

    return Loaded.load(demo_dir / "scenario.yaml")


def needs_reference():
    return pytest.mark.skipif(not REF.is_dir(), reason=f"the authors' reference maps are not at {REF} (../shared absent)")


@pytest.fixture(autouse=True)
def _console_width(monkeypatch):
    """Every test sees a console 200 columns wide, whatever the terminal that runs pytest (typer's
    help and error panels read COLUMNS; the CLI's own tables are 200 wide off a terminal), and
    the processes a test starts inherit it."""
    monkeypatch.setenv("COLUMNS", "200")
    monkeypatch.delenv("LINES", raising=False)


@pytest.fixture
def drawn(monkeypatch):
    """The figures the plot functions draw, kept open instead of written (closed after the test)."""
    figs = []
    monkeypatch.setattr(common, "_save", lambda fig, out, formats=("png",), dpi=common.PNG_DPI: figs.append(fig) or [])
    yield figs
    for f in figs:
        plt.close(f)


@pytest.fixture(autouse=True)
def _planner_registry():
    """A planner a test registers (a planner file, an entry point) is gone after it: the planner
    list that other tests pin is the package's own, whichever tests ran before in the process."""
    from semsearch_cli.planners import PLANNERS

    before = dict(PLANNERS)
    yield
    PLANNERS.clear()
    PLANNERS.update(before)
