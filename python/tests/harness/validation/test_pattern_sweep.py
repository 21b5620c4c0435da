"""The onset-of-patterns sweep (granular_shaker.patterns.sweep) and its report
(granular_shaker.reports.make_pattern_report): the summaries of a run and of a point on tables
of known values, and a whole sweep of a small box through `shaker`, resumed from its runs."""
import json
import os
import shutil

import numpy as np
import pytest

from granular_shaker.patterns import sweep
from granular_shaker.reports import make_pattern_report

from .. import REPOSITORY

TINY_SWEEP = """
[study.tiny]
cases = ["pattern_md_f0p25"]
gamma = [2.0, 2.4, 2.8, 3.2, 3.6]
seeds = [1]
overrides = ["layer.particles=300", "md.box_width=16.0", "md.box_depth=8.0",
             "run.transient_cycles=6", "run.sampled_cycles=4", "md.snapshot_cycles=[6, 7, 8, 9]"]
timeout = 300
"""


def tiny_repository(path):
    """A repository holding what the sweep reads: its definition, the case, the claims."""
    for folder in ("validation/cases", "reference-data"):
        os.makedirs(os.path.join(path, folder))
    for name in ("validation/studies.toml", "validation/cases/pattern_md_f0p25.toml",
                 "reference-data/claims.toml", "reference-data/pattern-claims.toml"):
        shutil.copy(os.path.join(REPOSITORY, name), os.path.join(path, name))
    with open(os.path.join(path, sweep.SWEEP_FILE), "w") as f:
        f.write(TINY_SWEEP)
    return path


def table(phase, order, correlation):
    rows = len(phase)
    return {"phase": np.array(phase, float), "mass_order_parameter": np.array(order, float),
            "mass_wavelength": np.full(rows, 16.0), "mass_a2": np.full(rows, 0.9),
            "mass_a4": np.full(rows, 0.8), "mass_a6": np.full(rows, 0.7),
            "mass_correlation_previous_cycle": np.array(correlation, float)}


def test_a_run_is_summarised_at_the_phase_of_the_larger_pattern():
    columns = table([0.0, 0.5, 0.0, 0.5, 0.0, 0.5], [0.1, 0.3, 0.2, 0.5, 0.3, 0.4],
                    [np.nan, np.nan, -0.9, -0.8, -1.0, -0.7])
    summary = sweep.frame_summary(columns)
    assert summary["phase"] == 0.5
    assert summary["order"] == pytest.approx(0.4)
    assert summary["order_error"] == pytest.approx(0.1 / np.sqrt(3))  # sd 0.1 over 3 frames
    assert summary["correlation_previous_cycle"] == pytest.approx(-0.75)  # NaN left out
    assert summary["frames"] == 3


def test_a_point_of_several_seeds_takes_their_spread_as_its_error():
    runs = [dict(order=x, order_error=1e-6, wavelength=16.0, a2=1.0, a4=1.0, a6=1.0,
                 correlation_previous_cycle=-1.0) for x in (0.2, 0.4)]
    point = sweep.point_summary(runs)
    assert point["order"] == pytest.approx(0.3)
    assert point["order_error"] == pytest.approx(0.1)  # sd 0.1414 / sqrt 2
    assert sweep.point_summary(runs[:1])["order_error"] == 1e-6


def test_an_unknown_study_is_refused(work_dir, shaker):
    with pytest.raises(SystemExit) as exit_info:
        sweep.main(["--shaker", shaker, "--study", "huge", "--repository",
                    tiny_repository(os.path.join(work_dir, "repository"))])
    assert exit_info.value.code == 2


def test_a_small_sweep_runs_resumes_and_reports(work_dir, shaker):
    repository = tiny_repository(os.path.join(work_dir, "repository"))
    workdir, report = os.path.join(work_dir, "work"), os.path.join(work_dir, "patterns.md")
    arguments = ["--shaker", shaker, "--study", "tiny", "--repository", repository,
                 "--workdir", workdir, "--jobs", "2", "--report", report]
    assert sweep.main(arguments) == 0
    with open(os.path.join(workdir, "patterns.json")) as f:
        first = json.load(f)
    points = first["cases"]["pattern_md_f0p25"]["points"]
    print("measured:", [(p["gamma"], round(p["order"], 4), round(p["order_error"], 4))
                        for p in points])
    assert [p["gamma"] for p in points] == [2.0, 2.4, 2.8, 3.2, 3.6]
    for p in points:
        # 300 particles on 8 x 4 cells: the column mass carries Poisson noise at least
        assert 0.0 < p["order"] < 10.0 and 0.0 < p["order_error"] < p["order"]
    onset = first["cases"]["pattern_md_f0p25"]["onset"]
    assert "gamma_c" in onset or "does not" in onset["reason"]
    assert all(not r["reused"] for r in first["runs"])
    # Resumed: every run reused, the same numbers.
    assert sweep.main(arguments + ["--reuse-only"]) == 0
    with open(os.path.join(workdir, "patterns.json")) as f:
        second = json.load(f)
    assert all(r["reused"] for r in second["runs"])
    assert second["cases"] == first["cases"]
    text = open(report).read()
    for claim in [f"P{i}" for i in range(1, 10)]:
        assert f"| {claim} (" in text
    assert ("ordered standing waves (A2" in text) != ("no ordered standing wave" in text)
    assert os.path.exists(os.path.join(work_dir, make_pattern_report.FIGURES,
                                       "order_parameter.png"))
