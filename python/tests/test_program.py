"""granular_shaker.program: finding the shaker program (SHAKER, else PATH) and running it."""
import os

import pytest

from granular_shaker.program import find_shaker, run_shaker


def test_no_program_names_what_to_set(monkeypatch, work_dir):
    monkeypatch.delenv("SHAKER", raising=False)
    monkeypatch.setenv("PATH", work_dir)
    with pytest.raises(FileNotFoundError, match="set the environment variable SHAKER"):
        find_shaker()
    monkeypatch.setenv("SHAKER", os.path.join(work_dir, "missing"))
    with pytest.raises(FileNotFoundError, match="missing: not an executable file"):
        find_shaker()


def test_run_from_the_environment_variable(monkeypatch, shaker, work_dir):
    monkeypatch.setenv("SHAKER", shaker)
    assert find_shaker() == shaker
    assert run_shaker("--version").startswith("shaker ")
    missing = os.path.join(work_dir, "missing.toml")
    with pytest.raises(RuntimeError, match=r"exited 2:\n.*missing\.toml"):
        run_shaker("md", missing)
