"""python tests/bare.py ARGS...: semsearch's CLI with every package that only an extra of
pyproject.toml installs hidden, as after a fresh ``pip install .`` (a finder in front of the
others finds nothing of them, so their import fails and ``find_spec`` says absent)."""

import importlib.abc
import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IMPORT_NAMES = {"scikit-learn": "sklearn", "mkdocs-material": "material", "import-linter": "importlinter",
                "dask-jobqueue": "dask_jobqueue", "opencv-python-headless": "cv2", "pyyaml": "yaml",
                "llama-cpp-python": "llama_cpp"}


def extra_packages() -> set[str]:
    """The top-level import names of every extra's packages that the base install does not need."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    name = lambda spec: re.split(r"[<>=!~\[ ;]", spec)[0].lower()
    base = {name(s) for s in project["dependencies"]}
    extra = {name(s) for specs in project["optional-dependencies"].values() for s in specs} - base - {"setuptools", "pip"}
    tops = {IMPORT_NAMES.get(n, n.replace("-", "_")) for n in extra}
    return tops | ({"dask"} if "distributed" in tops else set())


class Hidden(importlib.abc.MetaPathFinder):
    def __init__(self, tops: set[str]):
        self.tops = tops

    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in self.tops:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


if __name__ == "__main__":
    hidden = extra_packages()
    for m in [m for m in sys.modules if m.partition(".")[0] in hidden]:
        del sys.modules[m]
    sys.meta_path.insert(0, Hidden(hidden))
    sys.path.insert(0, str(ROOT))
    sys.argv[0] = "semsearch"
    from semsearch_cli.cli import main

    main()
