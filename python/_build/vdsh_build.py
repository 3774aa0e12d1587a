"""The build backend of python/ (PEP 517, pyproject.toml's backend-path):
setuptools.build_meta, run on a copy of python/ in a temporary folder, so
that `pip install ./python` leaves nothing behind in the checkout
(setuptools writes build/ and vdsh.egg-info/ beside pyproject.toml;
issue 26). Editable installs (`pip install -e`) point at the checkout
itself and so run in place, as setuptools' own."""
import contextlib
import os
import shutil
import tempfile

from setuptools import build_meta as _setuptools
from setuptools.build_meta import *  # noqa: F401,F403  (every hook, editable ones too)


@contextlib.contextmanager
def _copy():
    """Run the block in a copy of the source folder (the current one)."""
    here = os.getcwd()
    with tempfile.TemporaryDirectory(prefix="vdsh-py-build.") as tmp:
        work = os.path.join(tmp, "python")
        shutil.copytree(here, work, symlinks=True,
                        ignore=shutil.ignore_patterns("build", "dist", "*.egg-info",
                                                      "__pycache__"))
        os.chdir(work)
        try:
            yield
        finally:
            os.chdir(here)


def _out_of_tree(hook):
    def run(directory, *args, **kwargs):
        directory = os.path.abspath(directory)  # relative to the checkout
        with _copy():
            return hook(directory, *args, **kwargs)
    run.__name__ = hook.__name__
    run.__doc__ = hook.__doc__
    return run


get_requires_for_build_wheel = _setuptools.get_requires_for_build_wheel
get_requires_for_build_sdist = _setuptools.get_requires_for_build_sdist
prepare_metadata_for_build_wheel = _out_of_tree(_setuptools.prepare_metadata_for_build_wheel)
build_wheel = _out_of_tree(_setuptools.build_wheel)
build_sdist = _out_of_tree(_setuptools.build_sdist)
