"""The package installs with pip from Debian's setuptools, offline, and works from where it
was installed, in a process that does not see the source tree: its readers (pip --target) and
its commands (a fresh virtual environment, as python/README.md tells users)."""
import os
import subprocess
import tomllib

import synthetic_files as synthetic
from package_install import (PACKAGE_SOURCE, PYTHON, environment_with,
                             install_into_virtual_environment, install_package)

REPOSITORY = os.path.dirname(os.path.abspath(PACKAGE_SOURCE))
PROGRAM = """
import granular_shaker, granular_shaker.plotting, sys
run = granular_shaker.read_run(sys.argv[1], frame="plate")
print(granular_shaker.__file__)
print(run.profiles.units["n"], run.profiles["z"][1, 0])
"""


def test_pip_install_and_import_from_the_target(work_dir):
    target = install_package(work_dir)
    installed = sorted(os.listdir(target))
    assert "granular_shaker" in installed
    assert any(name.startswith("granular_shaker-0.1.0") and name.endswith(".dist-info")
               for name in installed), installed
    run = os.path.join(work_dir, "run.h5")
    profiles, _ = synthetic.write_md_run(run)
    elsewhere = os.path.join(work_dir, "elsewhere")
    os.mkdir(elsewhere)
    result = subprocess.run([PYTHON, "-c", PROGRAM, run], capture_output=True, text=True,
                            cwd=elsewhere, env=environment_with(target, MPLBACKEND="Agg"))
    assert result.returncode == 0, result.stderr
    module, values = result.stdout.splitlines()
    assert module == os.path.join(target, "granular_shaker", "__init__.py")
    units, z = values.split(" ", 2)[0], float(values.rsplit(" ", 1)[1])
    assert units == "1/sigma^3"
    assert z == profiles["z"][1, 0] - profiles["plate_z"][1]


def commands():
    """The commands the package declares ([project.scripts] of python/pyproject.toml)."""
    with open(os.path.join(PACKAGE_SOURCE, "pyproject.toml"), "rb") as f:
        return tomllib.load(f)["project"]["scripts"]


def test_commands_of_a_virtual_environment_install(work_dir):
    """Every command of the package runs from a fresh virtual environment, outside the
    repository and without the source tree on the path: --help exits 0, an unknown option 2;
    the validation study outside a repository, or with a case the repository does not have,
    exits 2 naming what is wrong."""
    environment = install_into_virtual_environment(work_dir)
    declared = commands()
    assert {"shaker-validation", "shaker-sensitivity", "shaker-validation-report",
            "shaker-sensitivity-report", "shaker-convergence-report", "shaker-benchmark-report",
            "shaker-base-case-report", "shaker-patterns",
            "shaker-pattern-report"} == set(declared), declared
    elsewhere = os.path.join(work_dir, "elsewhere")
    os.mkdir(elsewhere)
    plain = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}

    def run(*command):
        return subprocess.run(list(command), capture_output=True, text=True, cwd=elsewhere,
                              env=dict(plain, MPLBACKEND="Agg"))

    for name in declared:
        program = os.path.join(environment, "bin", name)
        shown = run(program, "--help")
        assert shown.returncode == 0 and shown.stdout.startswith(f"usage: {name}"), \
            f"{name} --help: exit {shown.returncode}\n{shown.stdout}{shown.stderr}"
        refused = run(program, "--no-such-option")
        assert refused.returncode == 2 and f"{name}: error: " in refused.stderr, \
            f"{name} --no-such-option: exit {refused.returncode}\n{refused.stderr}"
    python = os.path.join(environment, "bin", "python")
    where = run(python, "-c", "import granular_shaker.validation.cli as m; print(m.__file__)")
    assert where.stdout.strip().startswith(os.path.join(environment, "lib")), where.stdout
    assert run(python, "-m", "granular_shaker.validation", "--help").returncode == 0

    study = os.path.join(environment, "bin", "shaker-validation")
    outside = run(study, "--shaker", "shaker")
    assert outside.returncode == 2 and "--repository DIR" in outside.stderr, outside.stderr
    unknown = run(study, "--shaker", "shaker", "--repository", REPOSITORY, "--cases",
                  "no_such_case", "--workdir", os.path.join(work_dir, "study"))
    assert unknown.returncode == 2 and "unknown case(s) no_such_case" in unknown.stderr, \
        unknown.stderr
