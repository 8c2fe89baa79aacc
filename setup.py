"""Build hook (the rest of the build is pyproject.toml): a wheel or an sdist built from a git
checkout carries the commit it was built from, in ``semsearch_cli/data/build_commit.txt``, which
``semsearch --version`` and results' provenance (meta.json's ``commit``) read once the package is
installed outside the checkout. A wheel built from such an sdist (``python -m build``) keeps it.
The version itself stays the plain release (``0.2.0``): package indexes refuse local versions
such as ``0.2.0+g8b23c9a``."""

import importlib.util
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

ROOT = Path(__file__).resolve().parent
STAMP = Path("semsearch_cli") / "data" / "build_commit.txt"


def _checkout_module():
    """semsearch_cli/checkout.py, loaded by its path (the package's dependencies are not installed
    while it builds)."""
    spec = importlib.util.spec_from_file_location("semsearch_checkout", ROOT / "semsearch_cli" / "checkout.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def build_commit():
    """The checkout's commit, or the one an sdist made from a checkout carries, or None."""
    commit = _checkout_module().checkout_commit(ROOT / "semsearch_cli")
    if commit is None and (ROOT / STAMP).is_file():
        commit = (ROOT / STAMP).read_text().strip() or None
    return commit


COMMIT = build_commit()


class BuildPy(build_py):
    """build_py that also writes the commit into the built package (never into the checkout)."""

    def run(self):
        super().run()
        if COMMIT and not getattr(self, "editable_mode", False):
            (Path(self.build_lib) / STAMP).write_text(COMMIT + "\n")


class Sdist(sdist):
    """sdist that also writes the commit into the source tree it packs."""

    def make_release_tree(self, base_dir, files):
        super().make_release_tree(base_dir, files)
        if COMMIT:
            target = Path(base_dir) / STAMP
            target.unlink(missing_ok=True)  # a hard link to a checkout's file, if any: never write through it
            target.write_text(COMMIT + "\n")


setup(cmdclass={"build_py": BuildPy, "sdist": Sdist})
