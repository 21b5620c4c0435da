"""What the Python tests share (pytest loads this file for every test in the repository).

--shaker names the `shaker` program for the tests that run it (ctest passes the one it built),
--sample-writer the helper that writes the sample run file; without them those tests are
skipped. `work_dir` is a temporary directory that is removed when
the test passes and kept, its path printed, when it fails, so a green run leaves nothing in
the system temporary folder (pytest's own tmp_path keeps the last three runs) and a red one
can be inspected.
"""
import os
import shutil
import tempfile

import pytest


def pytest_addoption(parser):
    parser.addoption("--shaker", help="the shaker program the tests run")
    parser.addoption("--sample-writer",
                     help="write_sample_run_file, the helper that writes the sample run file")


@pytest.fixture(scope="session")
def shaker(request):
    path = request.config.getoption("--shaker")
    if not path:
        pytest.skip("needs --shaker PROGRAM")
    return os.path.abspath(path)


_FAILED = pytest.StashKey[bool]()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    # work_dir's teardown needs the verdict of the test's setup and call.
    report = (yield).get_result()
    if report.failed:
        item.stash[_FAILED] = True


@pytest.fixture
def work_dir(request):
    name = request.node.name.replace("/", "_").replace("[", "-").strip("]")[:60]
    path = tempfile.mkdtemp(prefix=f"shaker-pytest-{name}-")
    yield path
    if request.node.stash.get(_FAILED, False):
        print(f"files kept in {path} (the test failed)")
    else:
        shutil.rmtree(path, ignore_errors=True)
