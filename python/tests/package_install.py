"""Installs the package as a user would, with pip and setuptools from Debian, offline."""
import os
import shutil
import subprocess

PACKAGE_SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir)
PYTHON = "/usr/bin/python3"


def package_copy(work_dir):
    """A copy of python/ in work_dir/source, without tests and examples (pip builds in the
    source folder; the copy keeps the repository clean and parallel tests apart)."""
    source = os.path.join(work_dir, "source")
    shutil.copytree(PACKAGE_SOURCE, source,
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__", "tests",
                                                  "examples"))
    return source


def pip_install(python, *arguments):
    """`python -m pip install` offline, without build isolation or dependencies."""
    command = [python, "-m", "pip", "install", "--no-build-isolation", "--no-deps",
               "--no-index", "--quiet", *arguments]
    result = subprocess.run(command, capture_output=True, text=True,
                            env={**os.environ, "PIP_NO_CACHE_DIR": "1"})
    assert result.returncode == 0, f"{' '.join(command)}:\n{result.stdout}{result.stderr}"


def install_package(work_dir):
    """pip install --target into work_dir/site from a copy of python/. Returns the target
    folder."""
    target = os.path.join(work_dir, "site")
    pip_install(PYTHON, "--target", target, package_copy(work_dir))
    return target


def install_into_virtual_environment(work_dir):
    """A fresh virtual environment in work_dir/venv that sees Debian's numpy, h5py and
    matplotlib (--system-site-packages), with the package pip installed into it from a copy
    of python/, as python/README.md tells users. Returns the environment's folder."""
    environment = os.path.join(work_dir, "venv")
    subprocess.run([PYTHON, "-m", "venv", "--system-site-packages", environment], check=True,
                   capture_output=True)
    pip_install(os.path.join(environment, "bin", "python"), package_copy(work_dir))
    return environment


def environment_with(target, **extra):
    """This environment with only `target` on PYTHONPATH (not the repository's python/)."""
    return {**os.environ, "PYTHONPATH": target, **extra}
