"""The package installs with pip from Debian's setuptools, offline, and works from where it
was installed, in a process that does not see the source tree."""
import os
import subprocess

import synthetic_files as synthetic
from package_install import PYTHON, environment_with, install_package

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
