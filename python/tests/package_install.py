"""Installs the package as a user would, with pip and setuptools from Debian, offline."""
import os
import shutil
import subprocess

PACKAGE_SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir)
PYTHON = "/usr/bin/python3"


def install_package(work_dir):
    """pip install --target into work_dir/site from a copy of python/ (pip builds in the
    source folder; the copy keeps the repository clean and parallel tests apart). Returns the
    target folder."""
    source, target = os.path.join(work_dir, "source"), os.path.join(work_dir, "site")
    shutil.copytree(PACKAGE_SOURCE, source,
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__", "tests",
                                                  "examples"))
    command = [PYTHON, "-m", "pip", "install", "--no-build-isolation", "--no-deps",
               "--no-index", "--quiet", "--target", target, source]
    result = subprocess.run(command, capture_output=True, text=True,
                            env={**os.environ, "PIP_NO_CACHE_DIR": "1"})
    assert result.returncode == 0, f"{' '.join(command)}:\n{result.stdout}{result.stderr}"
    return target


def environment_with(target, **extra):
    """This environment with only `target` on PYTHONPATH (not the repository's python/)."""
    return {**os.environ, "PYTHONPATH": target, **extra}
