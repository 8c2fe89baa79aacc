"""Build hook (the rest of the build is pyproject.toml): a wheel built from a git checkout
carries the commit it was built from, in its version (``0.2.0+g8b23c9a``, a PEP 440 local
version; ``.dirty`` when the package's files differ from the commit) and in
``semsearch_cli/data/build_commit.txt``, which results' provenance reads (``semsearch --version``,
meta.json's ``commit``). Built from anything else (an sdist, a tarball), the version is the plain
release."""

import importlib.util
import re
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
RELEASE = re.search(r'^__version__ = "([^"]+)"', (ROOT / "semsearch_cli" / "__init__.py").read_text(), re.M).group(1)


def _checkout_module():
    """semsearch_cli/checkout.py, loaded by its path (the package's dependencies are not installed
    while it builds)."""
    spec = importlib.util.spec_from_file_location("semsearch_checkout", ROOT / "semsearch_cli" / "checkout.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


COMMIT = _checkout_module().checkout_commit(ROOT / "semsearch_cli")


class BuildPy(build_py):
    """build_py that also writes the commit into the built package (not into the checkout)."""

    def run(self):
        super().run()
        if COMMIT and not getattr(self, "editable_mode", False):
            (Path(self.build_lib) / "semsearch_cli" / "data" / "build_commit.txt").write_text(COMMIT + "\n")


def version():
    if not COMMIT:
        return RELEASE
    sha, _, dirty = COMMIT.partition("+")
    return f"{RELEASE}+g{sha[:7]}" + (".dirty" if dirty else "")


setup(version=version(), cmdclass={"build_py": BuildPy})
