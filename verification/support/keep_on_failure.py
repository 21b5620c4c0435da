"""The work folder of a standalone check script: kept for inspection when a check failed,
removed when every check passed, so a green ctest run leaves nothing in the system temporary
folder (the C++ tests do the same with support/test_directory.hpp, the pytest files with the
work_dir fixture of conftest.py).

ctest puts this folder on PYTHONPATH for every script test (cmake/ShakerTests.cmake), so a
script run by path imports it by name, under python3 as under ParaView's pvbatch:

    import keep_on_failure
    work = keep_on_failure.work_folder("shaker-checkpoints-md-")
    ...
    return keep_on_failure.finish(work, problems)
"""
import shutil
import tempfile


def work_folder(prefix):
    """A fresh folder in the system temporary folder whose name starts with `prefix`."""
    return tempfile.mkdtemp(prefix=prefix)


def finish(folder, problems, passed=""):
    """The script's exit status. With problems: prints how many and where `folder` is kept,
    returns 1. Without: removes `folder`, prints `passed` (if any), returns 0."""
    if problems:
        print(f"{len(problems)} problem(s); files kept in {folder}")
        return 1
    shutil.rmtree(folder)
    if passed:
        print(passed)
    return 0
