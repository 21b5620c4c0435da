"""pytest tests of the harness in the package: the validation study (validation/, run by ctest
as validation.*, defined in the repository's validation/CMakeLists.txt) and the report
generators (reports/, run by ctest as reports.*), with the synthetic run files they share."""
import copy
import os
import sys

# The repository these tests belong to: the data the harness reads (validation/,
# reference-data/, verification/) and the package's source (python/).
REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
PACKAGE_SOURCE = os.path.join(REPOSITORY, "python")


def package_environment(**extra):
    """This environment with the package's source first on PYTHONPATH, for the harness's
    commands run as `python3 -m granular_shaker...` in a child process."""
    path = [PACKAGE_SOURCE] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(path), **extra}


def harness_command(module, *args, repository=True):
    """The command line that runs a harness module as users run it (`python3 -m
    granular_shaker.<module>`), on this repository's data unless `repository` is False (for a
    command that reads none)."""
    return ([sys.executable, "-m", f"granular_shaker.{module}"]
            + (["--repository", REPOSITORY] if repository else []) + list(args))


def edited_copy(items, change):
    """A deep copy of `items` with `change` applied to it (a broken copy for a checker to
    reject)."""
    items = copy.deepcopy(items)
    change(items)
    return items
