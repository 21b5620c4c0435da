"""The onset-of-patterns sweep (granular_shaker.patterns.sweep) and its report
(granular_shaker.reports.make_pattern_report): the summaries of a run and of a point on tables
of known values, and a whole sweep of a small box through `shaker`, resumed from its runs."""
import json
import os
import shutil
import signal
import subprocess
import tomllib

import numpy as np
import pytest

from granular_shaker.patterns import onset as pattern_onset
from granular_shaker.patterns import sweep
from granular_shaker.reports import figure_rules, make_pattern_report
from granular_shaker.validation import run as run_module

from .. import REPOSITORY

TINY_MD = """
cases = ["pattern_md_f0p18"]
gamma = [2.0, 2.4, 2.8, 3.2, 3.6]
seeds = [1]
overrides = ["layer.particles=300", "md.box_width=16.0", "md.box_depth=8.0",
             "run.transient_cycles=6", "run.sampled_cycles=4", "md.snapshot_cycles=[6, 7, 8, 9]"]
timeout = 300
"""
TINY_SWEEP = "[study.tiny]\n" + TINY_MD + "\n[study.tinyc]\n" + TINY_MD + """
[study.tinyc.continuum]
cases = ["pattern_continuum_f0p18"]
gamma = [2.2, 2.6, 3.0, 3.4, 3.8]
seeds = [1]
overrides = ["layer.particles=2800", "md.box_width=64.0", "md.box_depth=8.0",
             "continuum.box_width=64.0", "continuum.box_depth=8.0", "continuum.cell_size=2.0",
             "continuum.ceiling=20.0", "run.transient_cycles=18", "run.sampled_cycles=2",
             "continuum.field_cycles=[0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19]"]
timeout = 300

[study.tinyc.continuum.saturation]
gamma = [3.4]
cycles = 12
frames = 3
timeout = 300

[study.tinyc.continuum.grid]
gamma = [3.4]
cells = [2.0, 1.0, 0.8]
timeout = 300
"""


def tiny_repository(path):
    """A repository holding what the sweep reads: its definition, the case, the claims."""
    for folder in ("validation/cases", "reference-data"):
        os.makedirs(os.path.join(path, folder))
    for name in ("validation/studies.toml", "validation/cases/pattern_md_f0p18.toml",
                 "validation/cases/pattern_continuum_f0p18.toml",
                 "reference-data/claims.toml", "reference-data/pattern-claims.toml"):
        shutil.copy(os.path.join(REPOSITORY, name), os.path.join(path, name))
    with open(os.path.join(path, sweep.SWEEP_FILE), "w") as f:
        f.write(TINY_SWEEP)
    return path


def table(phase, order, correlation):
    """A pattern table whose half-wavelength correlation is minus the plain one (sinusoids)."""
    rows = len(phase)
    return {"phase": np.array(phase, float), "mass_order_parameter": np.array(order, float),
            "mass_wavelength": np.full(rows, 16.0), "mass_a2": np.full(rows, 0.9),
            "mass_a4": np.full(rows, 0.8), "mass_a6": np.full(rows, 0.7),
            "mass_correlation_previous_cycle": np.array(correlation, float),
            "mass_half_wavelength_correlation": -np.array(correlation, float)}


def with_critical_mode(point, power, mode=6, box_length=128.0):
    """The point with spectra at phases 0 and 0.5: `power` in `mode` at phase 0 (10 % error),
    every other mode and phase at a counting-noise floor of 1e-4."""
    spectrum = [1e-4] * 16
    spectrum[mode - 1] = power
    return dict(point, box_length=box_length,
                mode_power={"0": spectrum, "0.5": [1e-4] * 16},
                mode_power_error={"0": [0.1 * v for v in spectrum], "0.5": [1e-5] * 16})


def test_a_run_is_summarised_at_the_phase_of_the_larger_pattern():
    columns = table([0.0, 0.5, 0.0, 0.5, 0.0, 0.5], [0.1, 0.3, 0.2, 0.5, 0.3, 0.4],
                    [np.nan, np.nan, -0.9, -0.8, -1.0, -0.7])
    summary = sweep.frame_summary(columns)
    assert summary["phase"] == 0.5
    assert summary["order"] == pytest.approx(0.4)
    assert summary["order_error"] == pytest.approx(0.1 / np.sqrt(3))  # sd 0.1 over 3 frames
    assert summary["correlation_previous_cycle"] == pytest.approx(-0.75)  # NaN left out
    # -0.8 and -0.7: sd 0.0707 over the 2 frames that have a previous cycle
    assert summary["correlation_error"] == pytest.approx(0.05)
    assert summary["half_wavelength_correlation"] == pytest.approx(0.75)
    assert summary["half_wavelength_error"] == pytest.approx(0.05)
    assert summary["frames"] == 3


def test_a_point_of_several_seeds_takes_their_spread_as_its_error():
    runs = [dict(order=x, order_error=1e-6, wavelength=16.0, a2=1.0, a4=1.0, a6=1.0,
                 correlation_previous_cycle=-x, correlation_error=1e-3,
                 half_wavelength_correlation=x, half_wavelength_error=2e-3) for x in (0.2, 0.4)]
    point = sweep.point_summary(runs)
    assert point["order"] == pytest.approx(0.3)
    assert point["order_error"] == pytest.approx(0.1)  # sd 0.1414 / sqrt 2
    assert point["correlation_error"] == pytest.approx(0.1)   # the seeds' spread, likewise
    assert sweep.point_summary(runs[:1])["order_error"] == 1e-6
    assert sweep.point_summary(runs[:1])["correlation_error"] == 1e-3   # one seed: its frames'
    assert point["half_wavelength_correlation"] == pytest.approx(0.3)
    assert point["half_wavelength_error"] == pytest.approx(0.1)
    assert sweep.point_summary(runs[:1])["half_wavelength_error"] == 2e-3


def test_seeds_that_disagree_make_a_coexisting_point_and_the_onset_is_the_first_ordered_seed():
    def run(correlation, wavelength):
        return dict(order=1.0, order_error=0.1, wavelength=wavelength, a2=0.9, a4=0.5, a6=0.5,
                    correlation_previous_cycle=-correlation, correlation_error=0.01,
                    half_wavelength_correlation=correlation, half_wavelength_error=0.01)
    disordered, ordered = run(0.1, 60.0), run(0.7, 20.0)
    both = sweep.point_summary([disordered, ordered])
    # The mean correlation (0.4) fails the test; one seed of two passes it.
    assert both["half_wavelength_correlation"] == pytest.approx(0.4)
    assert both["ordered_seeds"] == 1 and both["wavelength"] == 20.0   # the ordered seed's
    assert pattern_onset.ordered(both) and pattern_onset.coexisting(both)
    none = sweep.point_summary([disordered, disordered])
    every = sweep.point_summary([ordered, ordered])
    assert not pattern_onset.ordered(none) and not pattern_onset.coexisting(none)
    assert pattern_onset.ordered(every) and not pattern_onset.coexisting(every)
    assert none["wavelength"] == 60.0 and every["wavelength"] == 20.0
    points = [dict(gamma=g, **p) for g, p in
              zip([1.8, 1.9, 2.0, 2.1, 2.2], [none, none, both, both, every])]
    for i, p in enumerate(points):
        p["order"] = 1.0 + i   # one rising branch
    assert pattern_onset.order_bracket(dict(points=points))[2:] == (1.9, 2.0)
    text = "\n".join(make_pattern_report.case_lines("pattern_md_f0p14", dict(points=points)))
    # Identical orders: the error is the seeds' own (0.1 each), combined.
    assert "| 2 | 3 ± 0.071 | 2 (1) |" in text and "| 2.2 | 5 ± 0.071 | 2 (2) |" in text
    assert "coexist (the seeds disagree) at Gamma 2 (1 of 2 ordered), 2.1 (1 of 2 ordered)" \
        ": the onset is hysteretic" in text
    assert "- onset of order bracketed by the sweep: Gamma_c = 1.95" in text
    # Seeds that disagree past the order parameter's peak mark where the stripes give way.
    points.append(dict(gamma=2.3, **dict(both, order=2.0)))
    text = "\n".join(make_pattern_report.case_lines("pattern_md_f0p14", dict(points=points)))
    assert "at Gamma 2 (1 of 2 ordered), 2.1 (1 of 2 ordered): the onset is hysteretic" in text
    assert "at Gamma 2.3 (1 of 2 ordered): past the order parameter's peak, where the stripes " \
        "give way" in text


def test_a_pattern_table_without_the_half_wavelength_column_is_made_again(work_dir):
    run = os.path.join(work_dir, "run.h5")
    table = run + ".patterns.csv"
    old_header = "cycle [1],phase [1],mass_correlation_previous_cycle [1]\n"
    new_header = ("cycle [1],phase [1],mass_correlation_previous_cycle [1],"
                  "mass_half_wavelength_correlation [1]\n")
    with open(table, "w") as f:
        f.write("# an older shaker analyze\n" + old_header)
    fake = os.path.join(work_dir, "fake-shaker")
    with open(fake, "w") as f:   # writes the new header to the path after --patterns
        f.write(f"#!/bin/sh\nprintf '{new_header.strip()}\\n' > \"$4\"\n")
    os.chmod(fake, 0o755)
    assert not sweep.has_every_column(table)
    made, reason = sweep.analyze(fake, dict(status="ok", path=run))
    assert made == table and reason is None and sweep.has_every_column(table)
    with open(table) as f:
        assert f.read() == new_header


def test_a_run_that_cannot_be_read_names_the_step_that_failed(monkeypatch):
    columns = table([0.0, 0.0], [0.1, 0.2], [np.nan, -0.9])
    monkeypatch.setattr(sweep, "analyze", lambda shaker, record: ("run.csv", None))
    monkeypatch.setattr(sweep, "read_shaker_csv", lambda path: (columns,))
    monkeypatch.setattr(sweep, "column_mass_frames", lambda path: "frames")

    def fails(error):
        def raise_it(*args):
            raise error
        return raise_it

    def read(solver, kind=None):
        run = dict(solver=solver, record=dict(path="run.h5", status="ok"))
        if kind:
            run["kind"] = kind
        return sweep.read_run("shaker", run), run

    monkeypatch.setattr(sweep, "growth_summary", fails(sweep.NoGrowthFit("too short")))
    failure, run = read("continuum")
    assert failure == "no growth rate: too short" and "summary" not in run
    # A saturation run measures no growth: only its view fails.
    monkeypatch.setattr(sweep, "run_view", fails(ValueError("no frame")))
    failure, run = read("continuum", "saturation")
    assert failure == "no top view or spectrum: no frame" and run["summary"]["order"] > 0.0
    monkeypatch.setattr(sweep, "growth_summary", lambda frames: dict(rate=0.1))
    failure, run = read("continuum")
    assert failure == "no top view or spectrum: no frame" and run["growth"] == dict(rate=0.1)
    assert run["summary"]["final_order"] == pytest.approx(0.2)
    monkeypatch.setattr(sweep, "column_mass_frames", fails(OSError("unreadable")))
    failure, run = read("md")
    assert failure == "no top view or spectrum: unreadable" and "summary" in run
    monkeypatch.setattr(sweep, "analyze", lambda shaker, record: (None, "run timeout"))
    assert read("md")[0] == "run timeout"


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
    points = first["cases"]["pattern_md_f0p18"]["points"]
    print("measured:", [(p["gamma"], round(p["order"], 4), round(p["order_error"], 4))
                        for p in points])
    assert [p["gamma"] for p in points] == [2.0, 2.4, 2.8, 3.2, 3.6]
    for p in points:
        # 300 particles on 8 x 4 cells: the column mass carries Poisson noise at least
        assert 0.0 < p["order"] < 10.0 and 0.0 < p["order_error"] < p["order"]
    onset = first["cases"]["pattern_md_f0p18"]["onset"]
    assert "gamma_c" in onset or "does not" in onset["reason"] \
        or "rising branch holds" in onset["reason"] or "not the onset of order" in onset["reason"]
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
    # The results kept beside the report draw the same report again.
    kept = os.path.join(work_dir, make_pattern_report.FIGURES, make_pattern_report.RESULTS)
    with open(kept) as f:
        assert json.load(f)["cases"] == second["cases"]
    again = os.path.join(work_dir, "again.md")
    assert make_pattern_report.main(["--results", kept, "--output", again,
                                     "--repository", repository]) == 0
    assert open(again).read() == text
    assert os.path.exists(os.path.join(work_dir, make_pattern_report.FIGURES,
                                       "order_parameter.png"))


def test_the_experiments_wavelength_follows_the_dispersion_relation():
    relation = dict(offset=1.0, amplitude=2.0, exponent=1.0)
    # f sqrt(H) = 0.5 * 2 = 1: lambda = H (1 + 2) = 12
    assert make_pattern_report.experiment_wavelength(relation, 0.5, 4.0) == pytest.approx(12.0)
    # f sqrt(H) = 0.25 * 2 = 0.5: lambda = 4 (1 + 2 / 0.5) = 20
    assert make_pattern_report.experiment_wavelength(relation, 0.25, 4.0) == pytest.approx(20.0)


def test_a_pattern_case_gives_its_frequency_and_depth():
    frequency, depth = make_pattern_report.case_parameters(REPOSITORY, "pattern_md_f0p18")
    assert frequency == 0.18
    assert depth == pytest.approx(5.0, abs=0.01)  # 5600 particles on 128 x 8


def synthetic_case(wavelength, onset, ordered_below=False):
    """Points of a sweep with stripes (A2 1, correlation -1) above `onset`, noise below."""
    points = []
    for gamma in (2.0, 2.2, 2.4, 2.6, 2.8, 3.0):
        stripes = gamma > onset or (ordered_below and gamma == 2.0)
        points.append(dict(gamma=gamma, order=1.0 if stripes else 0.2, order_error=0.01, seeds=1,
                           wavelength=wavelength + {2.6: -0.5, 2.8: 0.5}.get(gamma, 0.0),
                           a2=1.0 if stripes else 0.2, a4=0.1, a6=0.1,
                           half_wavelength_correlation=0.95 if stripes else 0.0))
    return dict(points=points, onset=dict(gamma_c=onset, gamma_c_error=0.05, floor=0.04,
                                          slope=1.0, chi2_per_dof=1.0, points=len(points)))


def verdicts(cases, dispersion):
    with open(os.path.join(REPOSITORY, make_pattern_report.CLAIMS), "rb") as f:
        claims = tomllib.load(f)["claim"]
    parameters = {"pattern_md_f0p14": (0.14, 5.0), "pattern_md_f0p18": (0.18, 5.0)}
    return {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, parameters, dispersion)}


def test_the_md_part_of_the_wavelength_claims_is_judged():
    relation = dict(offset=1.0, amplitude=1.0, exponent=1.0)
    # lambda_exp = 5 (1 + 1 / (f sqrt 5)): 20.97 at f = 0.14, 17.4226 at f = 0.18
    cases = {"pattern_md_f0p18": synthetic_case(17.4226, 2.5),
             "pattern_md_f0p14": synthetic_case(25.0, 2.3)}
    rows = verdicts(cases, relation)
    assert rows["P1"]["verdict"] == "MD pass; continuum not measured"
    assert rows["P3"]["verdict"] == "MD pass; continuum not measured"
    assert "1.435 ± " in rows["P3"]["value"]  # 25 / 17.4226
    assert rows["P4"]["verdict"] == "MD pass; continuum not measured"
    assert "pattern_md_f0p14: 1.192" in rows["P4"]["value"]  # 25 / 20.97, in [0.8, 1.25]
    assert "pattern_md_f0p18: 1 " in rows["P4"]["value"]
    cases["pattern_md_f0p14"] = synthetic_case(30.0, 2.3)  # 30 / 20.97 = 1.43: too long
    assert verdicts(cases, relation)["P4"]["verdict"] == "MD fail; continuum not measured"
    for row in rows.values():  # claims the MD cannot judge alone stay unmeasured
        if row["id"] in ("P2", "P5", "P6", "P7", "P8"):
            assert row["verdict"] == "not measured" and row["reason"]


def test_stripes_below_the_onset_fail_the_md_part_of_p1():
    cases = {"pattern_md_f0p18": synthetic_case(21.3, 2.5, ordered_below=True),
             "pattern_md_f0p14": synthetic_case(25.6, 2.3)}
    assert verdicts(cases, None)["P1"]["verdict"] == "MD fail; continuum not measured"
    assert verdicts(cases, None)["P4"]["verdict"] == "not measured"  # no dispersion relation
    # Without an onset fit, ordered points that alternate with disordered ones bracket no
    # onset of order: that case fails the part, named; the other still measures it.
    alternating = synthetic_case(25.6, 2.3, ordered_below=True)
    alternating["onset"] = dict(reason="the best onset is at the end of the sweep")
    cases = {"pattern_md_f0p18": synthetic_case(21.3, 2.5), "pattern_md_f0p14": alternating}
    row = verdicts(cases, None)["P1"]
    assert row["verdict"] == "MD fail; continuum not measured"
    assert "pattern_md_f0p14: ordered at Gamma 2, 2.4, 2.6, 2.8, 3 (no onset of order: " \
        "ordered and disordered points alternate)" in row["value"] \
        and "pattern_md_f0p18: ordered at Gamma 2.6, 2.8, 3;" in row["value"]
    everywhere = synthetic_case(25.6, 1.5)   # ordered at every point of the sweep
    everywhere["onset"] = dict(reason="the best onset is at the end of the sweep")
    row = verdicts({**cases, "pattern_md_f0p14": everywhere}, None)["P1"]
    assert "pattern_md_f0p14: ordered at Gamma 2, 2.2, 2.4, 2.6, 2.8, 3 (no onset of order in " \
        "the sweep: ordered at every Gamma)" in row["value"]
    for point in alternating["points"]:
        point["a2"] = 0.2
    assert "pattern_md_f0p14: ordered at Gamma none (no ordered point)" in \
        verdicts(cases, None)["P1"]["value"]


def test_reports_and_figures_are_written_readable_by_others(work_dir):
    """Atomic writes go through a private temporary file; the report must not stay private."""
    from granular_shaker.reports import report_common
    previous = os.umask(0o022)
    try:
        path = os.path.join(work_dir, "report.md")
        report_common.write_text_atomically(path, "text\n")
        figure = make_pattern_report.figure_order_parameter(
            {"pattern_md_f0p18": {"points": [dict(gamma=g, order=0.5, order_error=0.01)
                                             for g in (2.0, 2.2)]}})
        picture = os.path.join(work_dir, "figure.png")
        report_common.save_figure_atomically(figure, picture)
    finally:
        os.umask(previous)
    assert os.stat(path).st_mode & 0o777 == 0o644
    assert os.stat(picture).st_mode & 0o777 == 0o644


def synthetic_continuum(onset, mode_wavelength=21.3333, slope=0.5):
    """A continuum sweep whose growth rate crosses zero at `onset`, its fastest mode growing
    above it; the order parameter of its last frame 1e-6 below onset."""
    points = []
    for gamma in (2.0, 2.2, 2.4, 2.6, 2.8, 3.0):
        points.append(dict(gamma=gamma, rate=slope * (gamma - onset), rate_error=0.01, mode=6,
                           mode_wavelength=mode_wavelength, fit_cycles=[5, 39],
                           final_order=1e-6 if gamma < onset else 0.1, order=0.1,
                           grid_scale_gain=30.0 if gamma == 3.0 else 0.01,
                           order_error=0.01, seeds=1, wavelength=21.3, a2=1.0, a4=1.0, a6=1.0,
                           half_wavelength_correlation=1.0))
    edge = dict(gamma_c=onset, gamma_c_error=0.02, slope=slope, slope_error=0.01,
                chi2_per_dof=1.0, points=4)
    growing = [p["gamma"] for p in points if p["gamma"] > onset]
    return dict(solver="continuum", points=points, onset=edge,
                bands=[dict(first_gamma=growing[0], last_gamma=growing[-1], lower=edge,
                            upper=None)] if growing else [])


def test_the_continuum_parts_and_the_comparisons_are_judged():
    relation = dict(offset=1.0, amplitude=1.0, exponent=1.0)  # 17.4226 sigma at f = 0.18
    md = synthetic_case(17.4226, 2.5)
    md["swift_hohenberg"] = dict(gamma_mf=2.32, gamma_mf_error=0.005)
    cases = {"pattern_md_f0p18": md, "pattern_md_f0p14": synthetic_case(25.0, 2.3),
             "pattern_continuum_f0p18": synthetic_continuum(2.3, mode_wavelength=17.4226)}
    parameters = {"pattern_continuum_f0p18": (0.18, 5.0)}
    with open(os.path.join(REPOSITORY, make_pattern_report.CLAIMS), "rb") as f:
        claims = tomllib.load(f)["claim"]
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    # P2: 2.5 / 2.3 = 1.087 +- 1.087 * hypot(0.05 / 2.5, 0.02 / 2.3) = 0.0237, in [1.04, 1.16]
    # but only 1.98 errors from its edge: within the 2 that decide, so unresolved
    assert rows["P2"]["verdict"] == "unresolved"
    assert rows["P2"]["value"] == "1.087 ± 0.024"
    # P8: 2.32 / 2.3 = 1.0087 ± 0.0094, 2.3 errors inside [0.97, 1.03]
    assert rows["P8"]["verdict"] == "pass"
    # P6 at Gamma 2.2, below both onsets: MD 0.2 against the continuum's 1e-6
    assert rows["P6"]["verdict"] == "pass" and rows["P6"]["value"].startswith("2e+05")
    assert rows["P1"]["verdict"] == "pass"  # MD stripes above 2.5, continuum growth above 2.3
    assert rows["P4"]["verdict"] == "pass" and "continuum: pattern_continuum_f0p18: 1 " in \
        rows["P4"]["value"]
    assert rows["P5"]["verdict"] == "not measured" and "linear stage" in rows["P5"]["reason"]
    # P5 with a saturation run at Gamma 2.8, above both onsets (the MD's 2.5): the MD's order
    # parameter there against 0.1 saturated
    saturated = dict(gamma=2.8, order=0.1, order_error=0.002, wavelength=17.0, a2=1.0,
                     correlation_previous_cycle=-0.9, half_wavelength_correlation=0.9)
    cases["pattern_continuum_f0p18"]["saturation"] = [saturated]
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    md_order = next(p["order"] for p in md["points"] if p["gamma"] == 2.8)
    assert rows["P5"]["verdict"] == ("pass" if not 0.8 <= md_order / 0.1 <= 1.25 else "fail")
    assert rows["P5"]["value"].startswith(f"{md_order / 0.1:.4g} ± ")
    # P9: the lower frequency's Swift-Hohenberg strength over the higher's, below 1 to pass.
    frequencies = {**parameters, "pattern_md_f0p14": (0.14, 5.0), "pattern_md_f0p18": (0.18, 5.0)}
    assert "needs Swift-Hohenberg fits at both" in rows["P9"]["reason"]
    # 0.5 ± 0.24 is 2.1 errors below 1; 1.5 ± 0.53 is 0.95 above; 3.33 ± 1.1 is 2.1 above
    for low, verdict in ((3e-6, "pass"), (9e-6, "unresolved"), (2e-5, "fail")):
        cases["pattern_md_f0p14"]["swift_hohenberg"] = dict(strength=low, strength_error=1e-6)
        md["swift_hohenberg"].update(strength=6e-6, strength_error=2e-6)
        p9 = next(row for row in make_pattern_report.claim_verdicts(
            claims, cases, frequencies, relation) if row["id"] == "P9")
        ratio = low / 6e-6
        error = ratio * np.hypot(1e-6 / low, 2e-6 / 6e-6)
        assert p9["verdict"] == verdict
        assert p9["value"].startswith(f"{ratio:.4g} ± {error:.2g} (strengths {low:.3g} ± 1e-06 "
                                      "at the lower frequency, 6e-06 ± 2e-06 at the higher)")
    saturated["order"] = md_order  # the same amplitude in both: P5 fails
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P5"]["verdict"] == "fail" and rows["P5"]["value"].startswith("1 ± ")
    saturated["gamma"] = 3.3  # no MD point there ...
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P5"]["verdict"] == "not measured" and "3.3" in rows["P5"]["reason"]
    saturated["gamma"] = 2.4  # ... nor above the MD's onset here (2.4 < 2.5)
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P5"]["verdict"] == "not measured" and "above its onset" in rows["P5"]["reason"]
    del cases["pattern_continuum_f0p18"]["saturation"]
    # the continuum's wavelength far from the experiments' fails P4 as a whole
    cases["pattern_continuum_f0p18"] = synthetic_continuum(2.3, mode_wavelength=64.0)
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P4"]["verdict"] == "fail"
    # a continuum whose rate rises, falls below zero and rises again fails its part of P1
    bent = synthetic_continuum(2.3)
    bent["points"][3]["rate"] = -0.05
    cases["pattern_continuum_f0p18"] = bent
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P1"]["verdict"] == "fail"
    assert "growth from Gamma_c 2.3; against it at Gamma 2.6" in rows["P1"]["value"]
    # ... but not when that rate is within two of its errors of zero (-0.015 +- 0.01)
    bent["points"][3]["rate"] = -0.015
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P1"]["verdict"] == "pass" and "against it" not in rows["P1"]["value"]
    # growth below the onset, in a band of its own, goes against P1 (Gamma 2.0 grows) ...
    banded = synthetic_continuum(2.3)
    banded["points"][0]["rate"] = 0.05
    banded["bands"].insert(0, dict(first_gamma=2.0, last_gamma=2.0, lower=None,
                                   upper=dict(gamma_c=2.1)))
    # ... where a decay above the top of the onset's band does not (Gamma 3.0 decays)
    banded["points"][-1]["rate"] = -0.05
    banded["bands"][1].update(last_gamma=2.8, upper=dict(gamma_c=2.9))
    cases["pattern_continuum_f0p18"] = banded
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P1"]["verdict"] == "fail"
    assert "growth from Gamma_c 2.3 to 2.9; against it at Gamma 2 " in rows["P1"]["value"] + " "
    # P6 compares the MD's noise with the continuum where it does not grow: at 2.2, not 2.0
    assert "continuum's last frame 1e-06 at Gamma 2.2" in rows["P6"]["value"]
    banded["points"][1]["rate"] = 0.05  # the low band now holds every point below the onset
    banded["bands"][0].update(last_gamma=2.2, upper=dict(gamma_c=2.25))
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {**parameters, "pattern_md_f0p14": (0.14, 5.0),
                        "pattern_md_f0p18": (0.18, 5.0)}, relation)}
    assert rows["P6"]["verdict"] == "not measured"


def test_a_report_with_the_continuum_shows_its_growth_rates(work_dir):
    results = dict(study="synthetic", commit="0" * 40, seconds=1.0, failures=[], runs=[],
                   sweep=dict(cases=["pattern_md_f0p18"], gamma=[2.0, 3.0], seeds=[1],
                              overrides=[], continuum=dict(cases=["pattern_continuum_f0p18"],
                                                           gamma=[2.0, 3.0], seeds=[1],
                                                           overrides=["a=1"])),
                   cases={"pattern_md_f0p18": synthetic_case(21.3, 2.5),
                          "pattern_continuum_f0p18": synthetic_continuum(2.3)})
    output = os.path.join(work_dir, "patterns.md")
    make_pattern_report.write(results, REPOSITORY, output)
    text = open(output).read()
    assert text.startswith("# Onset of patterns: MD and continuum sweeps")
    assert "### pattern_continuum_f0p18 (continuum)" in text
    assert "| 2.4 | 0.05 ± 0.01 | 6 | 21.33 | 5 to 39 | 0.1 | 0.01 |" in text
    assert "| 3 | 0.35 ± 0.01 | 6 | 21.33 | 5 to 39 | 0.1 | 30 |" in text
    assert "grid-scale gain above 1) at Gamma 3: the pattern there is not resolved" in text
    assert "- band of growth, points Gamma 2.4 to 3: from 2.3 ± 0.02 to beyond the sweep" in text
    assert ("- onset (the lower edge of the lowest band that has one): Gamma_c = 2.3000 ± 0.02"
            in text)
    assert os.path.exists(os.path.join(work_dir, make_pattern_report.FIGURES,
                                       "growth_rate.png"))


def test_the_onset_is_fitted_on_the_rising_branch_only():
    gamma = np.round(np.arange(2.0, 3.61, 0.1), 10)
    # M^2 = 0.04 + (Gamma - 2.45) above onset up to 3.2, then the amplitude falls again
    power = 0.04 + np.maximum(gamma - 2.45, 0.0) - 1.5 * np.maximum(gamma - 3.2, 0.0)
    points = [dict(gamma=g, order=float(np.sqrt(p)), order_error=0.01 * float(np.sqrt(p)))
              for g, p in zip(gamma, power)]
    assert [p["gamma"] for p in sweep.rising_branch(points)][-1] == 3.2
    onset = sweep.fits(points)["onset"]
    assert onset["gamma_c"] == pytest.approx(2.45, abs=0.005)
    assert onset["chi2_per_dof"] < 1e-6
    assert sweep.rising_branch([]) == []
    early = [dict(p, order=2.0 - 0.1 * i) for i, p in enumerate(points)]  # falls from the 1st
    assert "rising branch holds 1 points" in sweep.fits(early)["onset"]["reason"]


def test_a_fitted_onset_outside_the_bracket_of_ordered_points_is_not_the_onset_of_order():
    # The measured f = 0.18 sweep: the disordered layer's order parameter rises slowly to 2.1,
    # jumps into stripes at 2.2; the supercritical form puts its onset near 2.0, below the
    # disordered points at 2.05 and 2.1, with chi^2 per degree of freedom in the hundreds.
    measured = [(1.9, 0.5956, 0.017, 0.09), (2.0, 0.6749, 0.016, -0.02),
                (2.05, 0.7559, 0.014, -0.06), (2.1, 0.7367, 0.013, -0.18),
                (2.2, 1.201, 0.013, -0.70), (2.3, 1.693, 0.0044, -0.78),
                (2.4, 1.839, 0.0099, -0.79), (2.6, 1.975, 0.018, -0.75),
                (2.8, 2.029, 0.011, -0.72)]
    # Their critical mode (6, the stripes' 21.3 sigma in the 128 sigma box) at the noise floor
    # below 2.2 apart from a rise at 2.05: no divergence towards the onset.
    points = [with_critical_mode(dict(gamma=g, order=m, order_error=e, a2=1.0,
                                      half_wavelength_correlation=-c, wavelength=21.3),
                                 1e-2 if g >= 2.2 else 3e-4 if g == 2.05 else 1e-4)
              for g, m, e, c in measured]
    gamma, order, error = (np.array(column) for column in list(zip(*measured))[:3])
    fitted = pattern_onset.fit_onset(gamma, order, error)
    assert fitted.gamma_c + fitted.gamma_c_error < 2.1 and fitted.chi2_per_dof > 100
    found = sweep.fits(points)
    assert "gamma_c" not in found["onset"]
    assert "outside the sweep's bracket of ordered points, 2.1 to 2.2" in found["onset"]["reason"]
    # The critical mode below the bracket (1.9 to 2.1) does not diverge towards an onset.
    assert found["swift_hohenberg"]["below"] == 2.2
    assert (found["swift_hohenberg"]["mode"], found["swift_hohenberg"]["phase"]) == (6, "0")
    assert "do not grow towards" in found["swift_hohenberg"]["reason"]
    # The reduced study's two seeds, with Gamma 2.15 (disordered): the bracket is 2.15 to 2.2,
    # and the fit's onset, its error scaled by a chi^2 per degree of freedom in the hundreds,
    # reaches into it; the form is rejected by its chi^2 all the same, and the bracket stands.
    reduced = [(1.9, 0.6209, 0.025, 0.03), (2.0, 0.6465, 0.028, 0.02),
               (2.05, 0.7199, 0.036, 0.06), (2.1, 0.7049, 0.032, 0.11),
               (2.15, 0.7449, 0.012, 0.11), (2.2, 1.225, 0.024, 0.67),
               (2.3, 1.709, 0.015, 0.85), (2.4, 1.831, 0.0086, 0.88),
               (2.6, 1.931, 0.044, 0.88), (2.8, 2.043, 0.013, 0.90)]
    gamma, order, error = (np.array(column) for column in list(zip(*reduced))[:3])
    fitted = pattern_onset.fit_onset(gamma, order, error)
    assert fitted.gamma_c + fitted.gamma_c_error > 2.15 and fitted.chi2_per_dof > 100
    found = sweep.fits([with_critical_mode(dict(gamma=g, order=m, order_error=e, a2=1.0,
                                                half_wavelength_correlation=c, wavelength=21.3),
                                           1e-2 if g >= 2.2 else 1e-4)
                        for g, m, e, c in reduced])
    assert "does not describe the points" in found["onset"]["reason"]
    assert found["swift_hohenberg"]["below"] == 2.2
    # An onset inside the bracket stands: the supercritical form exact, onset 2.15.
    inside = [dict(p, order=float(np.sqrt(0.36 + 10.0 * max(p["gamma"] - 2.15, 0.0))))
              for p in points]
    assert sweep.fits(inside)["onset"]["gamma_c"] == pytest.approx(2.15, abs=1e-3)


def test_a_continuum_without_an_onset_is_named_as_the_reason():
    decaying = synthetic_continuum(5.0)  # every rate negative over Gamma 2 to 3
    decaying["onset"] = dict(reason="the growth rates do not change sign from negative to "
                                    "positive over Gamma 2 to 3")
    cases = {"pattern_md_f0p18": synthetic_case(21.3, 2.5),
             "pattern_md_f0p14": synthetic_case(25.6, 2.3),
             "pattern_continuum_f0p18": decaying}
    rows = verdicts(cases, None)
    assert rows["P2"]["verdict"] == "not measured"
    assert rows["P2"]["reason"].startswith("pattern_continuum_f0p18: no continuum onset: the "
                                           "growth rates do not change sign")
    assert rows["P1"]["verdict"] == "MD pass; continuum not measured"
    assert "no continuum onset" in rows["P1"]["reason"]


def test_a_continuum_at_a_coarser_cell_says_so_beside_its_verdicts():
    sweep_table = dict(continuum=dict(overrides=["continuum.cell_size=2.0",
                                                 "continuum.box_depth=8.0"]))
    note = make_pattern_report.coarse_continuum_note(sweep_table)
    assert note.startswith("the continuum ran at cell 2.0")
    assert make_pattern_report.coarse_continuum_note(dict(continuum=dict(overrides=[]))) == ""
    assert make_pattern_report.coarse_continuum_note({}) == ""
    with open(os.path.join(REPOSITORY, make_pattern_report.CLAIMS), "rb") as f:
        claims = tomllib.load(f)["claim"]
    cases = {"pattern_md_f0p18": synthetic_case(21.3, 2.5),
             "pattern_md_f0p14": synthetic_case(25.6, 2.3),
             "pattern_continuum_f0p18": synthetic_continuum(2.3)}
    rows = {row["id"]: row for row in make_pattern_report.claim_verdicts(
        claims, cases, {"pattern_md_f0p14": (0.14, 5.0), "pattern_md_f0p18": (0.18, 5.0),
                        "pattern_continuum_f0p18": (0.18, 5.0)}, None, note)}
    assert note in rows["P2"]["reason"] and note in rows["P1"]["reason"]
    assert note not in rows["P9"]["reason"]  # an MD-only claim


def test_without_an_onset_fit_the_md_onset_is_the_bracket_of_ordered_points():
    case = synthetic_case(21.3, 2.5)  # ordered at 2.6, 2.8, 3.0; disordered at 2.4 and below
    case["onset"] = dict(reason="the best onset is at the end of the sweep")
    middle, error, low, high = pattern_onset.order_bracket(case)
    assert (low, high) == (2.4, 2.6)
    assert middle == pytest.approx(2.5) and error == pytest.approx(0.2 / np.sqrt(12.0))
    assert make_pattern_report.md_onset(case) == (middle, error)
    assert make_pattern_report.stripes_above_onset_only(case) is True
    mixed = synthetic_case(21.3, 2.5, ordered_below=True)  # ordered at 2.0 too: no bracket
    mixed["onset"] = {}
    assert pattern_onset.order_bracket(mixed) is None
    # Past the order parameter's peak (2.8) the stripes may lose their order (3.0, the
    # measured sweep at f = 0.18 and Gamma 3.4): the bracket and P1 use the rising branch.
    for point in case["points"]:
        point["order"] = {2.6: 1.5, 2.8: 2.0, 3.0: 1.2}.get(point["gamma"], point["order"])
    case["points"][-1]["half_wavelength_correlation"] = 0.3
    assert pattern_onset.order_bracket(case)[2:] == (2.4, 2.6)
    assert make_pattern_report.stripes_above_onset_only(case) is True
    case["points"][-1]["order"] = 2.5   # a disordered point on the rising branch: no bracket
    assert pattern_onset.order_bracket(case) is None


def test_a_saturation_table_is_checked_and_planned():
    where = "[study.x.continuum.saturation]"
    good = dict(gamma=[3.4], cycles=300, frames=10, timeout=3600)
    sweep.check_saturation(good, where)
    for bad, message in ((dict(good, gamma=[]), "at least 1"),
                         (dict(good, gamma=[3.4, 3.0]), "increasing"),
                         (dict(good, frames=300), "2 <= frames < cycles"),
                         (dict(good, frames=1), "2 <= frames < cycles"),
                         (dict(good, cycles=300.5), "whole numbers")):
        with pytest.raises(ValueError, match=message):
            sweep.check_saturation(bad, where)
    with pytest.raises(ValueError, match="no 'cycles'"):
        sweep.check_saturation({k: v for k, v in good.items() if k != "cycles"}, where)
    assert sweep.saturation_overrides(dict(good, cycles=12, frames=3)) == [
        "run.transient_cycles=9", "run.sampled_cycles=3", "continuum.field_cycles=[9, 10, 11]"]
    continuum = dict(cases=["pattern_continuum_f0p18"], gamma=[2.2, 2.6, 3.0, 3.4, 3.8],
                     seeds=[1, 2], overrides=["continuum.cell_size=2.0"], timeout=60,
                     saturation=good)
    study = dict(cases=["pattern_md_f0p18"], gamma=[2.0, 2.4, 2.8, 3.2, 3.6], seeds=[1],
                 overrides=[], timeout=60, continuum=continuum)
    plan = sweep.plan_points(REPOSITORY, study)
    saturation = [r for r in plan if r["kind"] == "saturation"]
    assert len(plan) == 5 + 10 + 2 and len(saturation) == 2
    assert all(r["solver"] == "continuum" and r["gamma"] == 3.4 and r["timeout"] == 3600
               and "continuum.cell_size=2.0" in r["overrides"]
               and "run.transient_cycles=290" in r["overrides"] for r in saturation)


def test_a_sweep_with_the_continuum_runs_its_saturation_runs(work_dir, shaker):
    repository = tiny_repository(os.path.join(work_dir, "repository"))
    workdir, report = os.path.join(work_dir, "work"), os.path.join(work_dir, "patterns.md")
    assert sweep.main(["--shaker", shaker, "--study", "tinyc", "--repository", repository,
                       "--workdir", workdir, "--jobs", "2", "--report", report]) == 0
    with open(os.path.join(workdir, "patterns.json")) as f:
        results = json.load(f)
    case = results["cases"]["pattern_continuum_f0p18"]
    assert [p["gamma"] for p in case["points"]] == [2.2, 2.6, 3.0, 3.4, 3.8]
    assert all(np.isfinite(p["rate"]) and "view" in p for p in case["points"])
    # The growth runs' view is their last frame; the saturation run's its last 3 cycles.
    assert all(p["view"]["frames"] == 1 for p in case["points"])
    (saturated,) = case["saturation"]
    assert saturated["gamma"] == 3.4 and saturated["view"]["cycle"] == 11.0
    assert saturated["view"]["frames"] == 3 and saturated["order"] > 0.0
    assert "rate" not in saturated and len(results["runs"]) == 5 + 5 + 1 + 3
    # The grid check's run at the sweep's own cell (2, the box 8 deep) is its growth run.
    assert sum(r["reused"] for r in results["runs"]) == 1
    grid = {p["cell"]: p for p in case["grid"]}
    assert sorted(grid) == [0.8, 1.0, 2.0] and all(p["gamma"] == 3.4 for p in grid.values())
    assert grid[2.0]["rate"] == next(p["rate"] for p in case["points"] if p["gamma"] == 3.4)
    text = open(report).read()
    assert "- saturated at Gamma 3.4" in text and "Grid check" in text
    assert "| 3.4 | 0.8 | " in text


def test_a_grid_table_is_checked_and_a_reversed_growth_is_noted():
    where = "[study.x.continuum.grid]"
    good = dict(gamma=[3.4], cells=[2.0, 1.0, 0.5], timeout=60)
    sweep.check_grid(good, where)
    for bad, message in ((dict(good, cells=[2.0, 1.0]), "at least 3"),
                         (dict(good, cells=[1.0, 2.0, 0.5]), "decreasing"),
                         (dict(good, cells=[2.0, 1.0, 0.0]), "> 0"),
                         (dict(good, gamma=[]), "at least 1")):
        with pytest.raises(ValueError, match=message):
            sweep.check_grid(bad, where)
    assert sweep.grid_overrides(0.8) == ["continuum.cell_size=0.8", "continuum.box_depth=3.2"]
    case = synthetic_continuum(2.3)   # grows at 2.6 at +0.15 +- 0.01
    case["grid"] = [dict(cell=c, gamma=2.6, rate=r, rate_error=0.01, mode=6, fit_cycles=[5, 39])
                    for c, r in ((2.0, 0.05), (1.0, 0.03), (0.5, -0.04))]
    assert make_pattern_report.reversals(case, "grid") == [(2.6, pytest.approx(0.15), 0.5,
                                                            -0.04)]
    note = make_pattern_report.check_note({"pattern_continuum_f0p18": case})
    assert note == ("pattern_continuum_f0p18: refinement reverses the growth at Gamma 2.6 (0.15 "
                    "per cycle at the sweep's cell, -0.04 at cell 0.5), so its onset there is "
                    "not the converged continuum's")
    lines = make_pattern_report.continuum_case_lines("pattern_continuum_f0p18", case)
    assert "- refinement reverses the growth at Gamma 2.6 (0.15 per cycle at the sweep's " \
        "cell, -0.04 at cell 0.5), so its onset there is not the converged continuum's" in lines
    case["grid"][-1]["rate"] = -0.015   # within two errors of zero: no reversal
    assert make_pattern_report.reversals(case, "grid") == []
    assert make_pattern_report.check_note({"pattern_continuum_f0p18": case}) == ""
    assert "- the grid check keeps the sign of every growth rate checked" in \
        make_pattern_report.continuum_case_lines("pattern_continuum_f0p18", case)
    case["grid"] = case["grid"][:1]   # the sweep's own cell only
    assert "- no run at a finer cell has finished: the grid check is incomplete" in \
        make_pattern_report.continuum_case_lines("pattern_continuum_f0p18", case)


def test_a_scheme_table_is_checked_planned_and_a_reversed_growth_is_noted():
    where = "[study.x.continuum.scheme]"
    good = dict(gamma=[3.4], limiters=["minmod", "van_leer"], timeout=60)
    sweep.check_scheme(good, where)
    for bad, message in ((dict(good, limiters=[]), "one or more"),
                         (dict(good, limiters=["minmod", "minmod"]), "distinct"),
                         (dict(good, limiters=["none"]), "minmod, van_leer, mc, first_order"),
                         (dict(good, gamma=[]), "at least 1")):
        with pytest.raises(ValueError, match=message):
            sweep.check_scheme(bad, where)
    with pytest.raises(ValueError, match="no 'limiters'"):
        sweep.check_scheme(dict(gamma=[3.4], timeout=60), where)
    continuum = dict(cases=["pattern_continuum_f0p18"], gamma=[2.2, 2.6, 3.0, 3.4, 3.8],
                     seeds=[1], overrides=[], timeout=60, scheme=good)
    study = dict(cases=["pattern_md_f0p18"], gamma=[2.0, 2.4, 2.8, 3.2, 3.6], seeds=[1],
                 overrides=[], timeout=60, continuum=continuum)
    scheme = [r for r in sweep.plan_points(REPOSITORY, study) if r["kind"] == "scheme"]
    assert [(r["limiter"], r["gamma"]) for r in scheme] == [("minmod", 3.4), ("van_leer", 3.4)]
    assert all("continuum.limiter=" + r["limiter"] in r["overrides"] for r in scheme)
    # Collected as the grid check is: one point per limiter and Gamma, from its first seed.
    for run in scheme:
        run["growth"] = dict(rate=-0.06 if run["limiter"] == "van_leer" else 0.01,
                             rate_error=0.01, mode=7, fit_cycles=[5, 39], grid_scale_gain=0.1)
    points = sweep.check_points(scheme, "pattern_continuum_f0p18", "scheme", "limiter")
    case = synthetic_continuum(2.3)   # grows at 3.0 at +0.35 +- 0.01
    case["scheme"] = [dict(p, gamma=3.0) for p in points]
    assert make_pattern_report.reversals(case, "scheme") == [
        (3.0, pytest.approx(0.35), "van_leer", -0.06)]   # minmod's +0.01 is within its errors
    note = make_pattern_report.check_note({"pattern_continuum_f0p18": case})
    assert note == ("pattern_continuum_f0p18: another slope limiter reverses the growth at "
                    "Gamma 3 (0.35 per cycle with the sweep's limiter, -0.06 with van_leer), so "
                    "the growth there is the scheme's, not the equations'")
    lines = make_pattern_report.continuum_case_lines("pattern_continuum_f0p18", case)
    assert "| 3 | minmod | 0.01 ± 0.01 | 7 | 5 to 39 | 0.1 |" in lines
    assert "Scheme check (the same run with other slope limiters at the sweep's cell):" in lines


def test_the_figures_show_the_continuum_case_its_checks_keep_and_the_md_case_at_its_frequency():
    view = dict(view={})
    doubted = synthetic_continuum(2.3)
    doubted["grid"] = [dict(cell=0.5, gamma=p["gamma"], rate=-0.5, rate_error=0.01, mode=6,
                            fit_cycles=[5, 39], grid_scale_gain=0.01)
                       for p in doubted["points"] if p["rate"] > 0]
    kept = synthetic_continuum(2.1)
    for case in (doubted, kept):
        case["points"][0].update(view)
    md_high, md_low = (dict(synthetic_case(w, 2.5), solver="md") for w in (21.3, 25.6))
    for case in (md_high, md_low):
        case["points"][0].update(view)
    cases = {"pattern_md_f0p18": md_high, "pattern_md_f0p14": md_low,
             "pattern_continuum_f0p18": doubted, "pattern_continuum_f0p14": kept}
    parameters = {"pattern_md_f0p18": (0.18, 5.0), "pattern_md_f0p14": (0.14, 5.0),
                  "pattern_continuum_f0p18": (0.18, 5.0), "pattern_continuum_f0p14": (0.14, 5.0)}
    assert make_pattern_report.caveats(doubted, True) and not make_pattern_report.caveats(kept)
    shown = make_pattern_report.shown_cases(cases, parameters)
    assert (shown["continuum"][0], shown["md"][0]) == ("pattern_continuum_f0p14",
                                                       "pattern_md_f0p14")
    # Without frequencies, or with every continuum case in doubt, the first of each.
    shown = make_pattern_report.shown_cases(dict(cases, pattern_continuum_f0p14=doubted))
    assert (shown["continuum"][0], shown["md"][0]) == ("pattern_continuum_f0p18",
                                                       "pattern_md_f0p18")


def test_the_onsets_are_compared_at_each_frequency_both_solvers_ran():
    md = dict(synthetic_case(21.3, 2.5), solver="md")   # onset 2.5 +- 0.05
    continuum = synthetic_continuum(2.3)                 # onset 2.3 +- 0.02
    continuum["scheme"] = [dict(limiter="minmod", gamma=3.0, rate=-0.05, rate_error=0.005,
                                mode=5, fit_cycles=[5, 39], grid_scale_gain=0.01)]
    cases = {"pattern_md_f0p18": dict(md, swift_hohenberg=dict(gamma_mf=2.4, gamma_mf_error=0.1)),
             "pattern_md_f0p14": dict(md), "pattern_continuum_f0p18": continuum}
    parameters = {"pattern_md_f0p18": (0.18, 5.0), "pattern_md_f0p14": (0.14, 5.0),
                  "pattern_continuum_f0p18": (0.18, 5.0)}
    lines = make_pattern_report.onset_ratio_lines(cases, parameters)
    rows = [line for line in lines if line.startswith("| 0.")]
    assert len(rows) == 1   # no continuum at f = 0.14
    ratio, error = 2.5 / 2.3, 2.5 / 2.3 * np.hypot(0.05 / 2.5, 0.02 / 2.3)
    mean_field, mean_field_error = 2.4 / 2.3, 2.4 / 2.3 * np.hypot(0.1 / 2.4, 0.02 / 2.3)
    assert rows[0].startswith(f"| 0.18 | 2.5 ± 0.05 | 2.4 ± 0.1 | 2.3 ± 0.02 | {ratio:.4g} ± "
                              f"{error:.2g} | {mean_field:.4g} ± {mean_field_error:.2g} | "
                              "another slope limiter reverses the growth at Gamma 3")
    # Without a Swift-Hohenberg fit its columns are n/a.
    bare = make_pattern_report.onset_ratio_lines(dict(cases, pattern_md_f0p18=md), parameters)
    assert "| 0.18 | 2.5 ± 0.05 | n/a | 2.3 ± 0.02 |" in "\n".join(bare)
    assert make_pattern_report.onset_ratio_lines({"pattern_md_f0p18": md}, parameters) == []


def test_a_limiter_that_reverses_growth_refinement_keeps_hides_the_equations_growth():
    case = synthetic_continuum(2.3)   # grows at 3.0 at +0.35 +- 0.01
    case["scheme"] = [dict(limiter="minmod", gamma=3.0, rate=-0.05, rate_error=0.005, mode=5,
                           fit_cycles=[5, 39], grid_scale_gain=0.01)]
    case["grid"] = [dict(cell=c, gamma=3.0, rate=r, rate_error=0.002, mode=5,
                         fit_cycles=[5, 39], grid_scale_gain=0.01)
                    for c, r in ((1.0, 0.069), (0.8, 0.063))]
    assert make_pattern_report.caveats(case) == [
        "another slope limiter reverses the growth at Gamma 3 (0.35 per cycle with the sweep's "
        "limiter, -0.05 with minmod), but refinement keeps it (0.063 per cycle at cell 0.8): "
        "the limiter's own dissipation at the sweep's cell hides growth that is the equations'"]
    # It does not put the growth in doubt: no caveat on the verdicts.
    assert make_pattern_report.check_note({"pattern_continuum_f0p14": case}) == ""
    case["grid"][-1]["rate"] = 0.003   # the finest cell's growth within two errors of zero
    note = make_pattern_report.check_note({"pattern_continuum_f0p14": case})
    assert "so the growth there is the scheme's" in note
    # A verdict carries the caveats of its own claim's continuum cases only.
    assert make_pattern_report.check_note({"pattern_continuum_f0p14": case},
                                          ["pattern_continuum_f0p18"]) == ""
    assert make_pattern_report.check_note({"pattern_continuum_f0p14": case},
                                          ["pattern_continuum_f0p14"]) == note


def test_a_check_table_may_give_each_case_its_own_gamma():
    where = "[study.x.continuum.scheme]"
    table = dict(gamma={"pattern_continuum_f0p18": [3.4], "pattern_continuum_f0p14": [2.2, 3.4]},
                 limiters=["minmod"], timeout=60)
    sweep.check_scheme(table, where)
    for bad in ({"pattern_continuum_f0p14": []}, {"pattern_continuum_f0p14": [3.4, 2.2]},
                {"pattern_continuum_f0p14": 2.2}):
        with pytest.raises(ValueError, match=r"gamma.pattern_continuum_f0p14 .*one per case"):
            sweep.check_scheme(dict(table, gamma=bad), where)
    continuum = dict(cases=["pattern_continuum_f0p18", "pattern_continuum_f0p14"],
                     gamma=[2.2, 2.6, 3.0, 3.4, 3.8], seeds=[1], overrides=[], timeout=60,
                     scheme=table)
    study = dict(cases=["pattern_md_f0p18"], gamma=[2.0, 2.4, 2.8, 3.2, 3.6], seeds=[1],
                 overrides=[], timeout=60, continuum=continuum)
    scheme = [(r["case"], r["gamma"]) for r in sweep.plan_points(REPOSITORY, study)
              if r["kind"] == "scheme"]
    assert scheme == [("pattern_continuum_f0p18", 3.4), ("pattern_continuum_f0p14", 2.2),
                      ("pattern_continuum_f0p14", 3.4)]


def test_a_grid_or_saturation_table_may_name_some_of_the_continuums_cases(work_dir):
    repository = tiny_repository(os.path.join(work_dir, "repository"))
    study = tomllib.loads(TINY_SWEEP)["study"]["tinyc"]
    study["continuum"]["grid"]["cases"] = []
    assert all(r["kind"] != "grid" for r in sweep.plan_points(repository, study))
    with open(os.path.join(repository, sweep.SWEEP_FILE), "a") as f:
        continuum = TINY_SWEEP.split("[study.tinyc.continuum]")[1].replace("tinyc", "wrong")
        f.write("\n[study.wrong]\n" + TINY_MD + "\n[study.wrong.continuum]" + continuum.replace(
            "cells = [2.0, 1.0, 0.8]", 'cases = ["pattern_md_f0p18"]\ncells = [2.0, 1.0, 0.8]'))
    with pytest.raises(ValueError, match=r"continuum.grid\]: cases \['pattern_md_f0p18'\]"):
        sweep.load_sweep(repository, "wrong")


def test_without_an_onset_fit_the_swift_hohenberg_fit_takes_the_points_below_the_bracket(
        monkeypatch):
    # The critical mode's power below the onset of order in the Swift-Hohenberg form towards
    # Gamma_mf = 2.3, then ordered stripes from 2.2 whose amplitude the supercritical form
    # cannot place; the order parameter below onset flat (the counting noise of every mode).
    gamma_mf, floor, strength = 2.3, 1e-4, 2e-5
    points = [with_critical_mode(dict(gamma=g, order=0.6, a2=1.0, half_wavelength_correlation=0.0),
                                 floor + strength * gamma_mf / (gamma_mf - g))
              for g in (1.8, 1.9, 2.0, 2.1)]
    points += [with_critical_mode(dict(gamma=g, order=1.5 + 0.1 * (g - 2.2), a2=1.0,
                                       half_wavelength_correlation=0.8), 0.05)
               for g in (2.2, 2.4, 2.6, 2.8)]
    for point in points:
        point.update(order_error=1e-3 * point["order"], seeds=1, wavelength=21.3)

    def no_onset(*args):
        raise sweep.NoOnset("the best onset is at the end of the sweep")
    monkeypatch.setattr(sweep, "fit_onset", no_onset)
    found = sweep.fits(points)
    assert "reason" in found["onset"]
    fit = found["swift_hohenberg"]
    assert fit["points"] == 4  # 1.8 to 2.1: below the bracket's first ordered point, 2.2
    assert fit["gamma_mf"] == pytest.approx(gamma_mf, abs=2e-3)
    assert fit["strength"] == pytest.approx(strength, rel=0.02)
    assert (fit["mode"], fit["phase"]) == (6, "0")
    lines = make_pattern_report.case_lines("pattern_md_f0p18", dict(points=points, **found))
    assert any(line.startswith("- Swift-Hohenberg fit below onset: gamma_mf = 2.30")
               and "noise power strength = 2e-05" in line and "mode 6 at phase 0" in line
               for line in lines)
    figure = make_pattern_report.figure_critical_mode(
        {"pattern_md_f0p18": dict(solver="md", points=points, **found)})
    curve = next(line for line in figure.axes[0].lines
                 if "Swift-Hohenberg fit below onset, Gamma_mf = 2.300" in line.get_label())
    assert curve.get_xdata().max() == pytest.approx(2.1)  # the highest point fitted
    assert curve.get_ydata()[0] == pytest.approx(points[0]["mode_power"]["0"][5], rel=1e-3)
    assert figure_rules.figure_problems(figure) == []
    # The spectra figure shows a point's mean over its seeds where it has one.
    point = dict(points[0], view=dict(spectrum_phase=0.0, frames=10, power=[1.0] * 16,
                                      power_error=[0.1] * 16), seeds=2)
    power, error, over = make_pattern_report.md_spectrum(point)
    assert power[5] == pytest.approx(points[0]["mode_power"]["0"][5]) and error[0] == 1e-5
    assert over == "2 seeds of 10 frames"
    power, error, over = make_pattern_report.md_spectrum(
        {k: v for k, v in point.items() if k != "mode_power"})
    assert list(power) == [1.0] * 16 and over == "10 frames"
    # Without spectra at the first ordered point no mode is critical: no fit, and why.
    bare = [{k: v for k, v in p.items() if k != "mode_power"} for p in points]
    assert "no spectra at the first ordered point" in sweep.fits(bare)["swift_hohenberg"][
        "reason"]
    for point in points[:4]:  # one of them ordered: no bracket, no Swift-Hohenberg fit
        point["half_wavelength_correlation"] = 0.8 if point["gamma"] == 1.9 else 0.0
    assert "swift_hohenberg" not in sweep.fits(points)


def test_an_extra_table_is_checked_and_its_points_planned_first_and_sorted_in():
    study = dict(cases=["pattern_md_f0p18", "pattern_md_f0p14"], gamma=[2.0, 2.1, 2.2, 2.3, 2.4],
                 seeds=[1, 2], overrides=["run.transient_cycles=120"], timeout=60)
    good = dict(cases=["pattern_md_f0p18"], gamma=[1.8, 1.9, 2.15], timeout=14400)
    where = "[study.x.extra]"
    sweep.check_extra(good, study, where)
    for bad, message in ((dict(good, gamma=[]), "at least 1"),
                         (dict(good, gamma=[1.9, 1.8]), "increasing"),
                         (dict(good, gamma=[1.8, 2.0]), "none of the sweep's own"),
                         (dict(good, cases=["pattern_md_f0p10"]), "not the sweep's"),
                         (dict(timeout=60, gamma={"pattern_md_f0p14": [2.2]}), "sweep's own"),
                         (dict(timeout=60, gamma={"pattern_md_f0p10": [1.8]}), "not the sweep's")):
        with pytest.raises(ValueError, match=message):
            sweep.check_extra(bad, study, where)
    with pytest.raises(ValueError, match="no 'cases'"):
        sweep.check_extra(dict(timeout=60, gamma=[1.8]), study, where)
    with pytest.raises(ValueError, match="no 'timeout'"):
        sweep.check_extra({k: v for k, v in good.items() if k != "timeout"}, study, where)
    plan = sweep.plan_points(REPOSITORY, dict(study, extra=good))
    assert len(plan) == 2 * 5 * 2 + 3 * 2
    first = plan[:4]  # the longest runs start first
    assert [(r["case"], r["gamma"], r["seed"]) for r in first] == [
        ("pattern_md_f0p18", 1.8, 1), ("pattern_md_f0p18", 1.8, 2),
        ("pattern_md_f0p18", 1.9, 1), ("pattern_md_f0p18", 1.9, 2)]
    assert all(r["kind"] == "sweep" and r["timeout"] == 14400
               and "run.transient_cycles=120" in r["overrides"] for r in first)
    # the points of a case come in increasing Gamma, the extra ones among them
    for run in plan:
        run["summary"] = dict(order=run["gamma"], order_error=0.01, wavelength=21.0, a2=1.0,
                              a4=1.0, a6=1.0, correlation_previous_cycle=-0.9,
                              half_wavelength_correlation=0.9)
    gammas = [p["gamma"] for p in sweep.case_points(plan, "pattern_md_f0p18")]
    assert gammas == [1.8, 1.9, 2.0, 2.1, 2.15, 2.2, 2.3, 2.4]
    # Gamma by case: each case's own extra points.
    by_case = dict(timeout=60, gamma={"pattern_md_f0p18": [2.15], "pattern_md_f0p14": [1.8]})
    sweep.check_extra(by_case, study, where)
    plan = sweep.plan_points(REPOSITORY, dict(study, extra=by_case))
    extra = [(r["case"], r["gamma"]) for r in plan[:4]]
    assert extra == [("pattern_md_f0p18", 2.15)] * 2 + [("pattern_md_f0p14", 1.8)] * 2
    # The report names them, in either form.
    assert make_pattern_report.extra_points(dict(study, extra=by_case)) == (
        ", pattern_md_f0p18 also at Gamma 2.15, pattern_md_f0p14 also at Gamma 1.8")
    assert make_pattern_report.extra_points(dict(study, extra=good)) == (
        ", pattern_md_f0p18 also at Gamma 1.8, 1.9, 2.15")
    assert make_pattern_report.extra_points(study) == ""


def test_several_extra_tables_each_with_its_own_overrides():
    study = dict(cases=["pattern_md_f0p18", "pattern_md_f0p14"], gamma=[2.0, 2.1, 2.2, 2.3, 2.4],
                 seeds=[1, 2], timeout=60,
                 overrides=["run.transient_cycles=120", "run.sampled_cycles=10"])
    far = dict(gamma={"pattern_md_f0p14": [1.8]}, timeout=14400,
               overrides=["run.transient_cycles=40", "md.snapshot_cycles=[40, 41]"])
    near = dict(gamma={"pattern_md_f0p14": [1.925, 1.95]}, timeout=7200)
    where = "[study.x.extra]"
    sweep.check_extra_tables(dict(study, extra=[far, near]), where)
    for tables, message in (([far, dict(near, gamma={"pattern_md_f0p14": [1.8, 1.95]})],
                             r"\(table 2\): points \[\('pattern_md_f0p14', 1.8\)\] are in an "
                             "earlier extra table too"),
                            ([dict(far, overrides=["run.transient_cycles"])],
                             r"\(table 1\): overrides: 'run.transient_cycles': allowed: "
                             "'key=value'"),
                            ([dict(far, overrides=[40])], "overrides: 40: allowed")):
        with pytest.raises(ValueError, match=message):
            sweep.check_extra_tables(dict(study, extra=tables), where)
    plan = sweep.plan_points(REPOSITORY, dict(study, extra=[far, near]))
    assert len(plan) == 2 * 5 * 2 + 3 * 2
    assert [(r["gamma"], r["seed"], r["timeout"]) for r in plan[:6]] == [
        (1.8, 1, 14400), (1.8, 2, 14400), (1.925, 1, 7200), (1.925, 2, 7200),
        (1.95, 1, 7200), (1.95, 2, 7200)]
    # The table's own overrides replace the sweep's of the same key, the others stay.
    assert plan[0]["overrides"] == ["shaker.gamma=1.8", "run.seed=1", "run.sampled_cycles=10",
                                    "run.transient_cycles=40", "md.snapshot_cycles=[40, 41]"]
    assert plan[2]["overrides"] == ["shaker.gamma=1.925", "run.seed=1",
                                    "run.transient_cycles=120", "run.sampled_cycles=10"]
    assert all(r["overrides"][2:] == study["overrides"] for r in plan[6:])
    assert make_pattern_report.extra_points(dict(study, extra=[far, near])) == (
        ", pattern_md_f0p14 also at Gamma 1.8 (with `run.transient_cycles=40`, "
        "`md.snapshot_cycles=[40, 41]`), pattern_md_f0p14 also at Gamma 1.925, 1.95")


@pytest.mark.parametrize("name", ["full", "reduced", "bracket"])
def test_every_study_of_the_repository_loads_and_plans(name):
    study = sweep.load_sweep(REPOSITORY, name)
    plan = sweep.plan_points(REPOSITORY, study)
    md = [r for r in plan if r["solver"] == "md"]
    extra_points = {(case, g) for extra in sweep.extra_tables(study)
                    for case in sweep.table_cases(study, extra) for g in sweep.gammas(extra, case)}
    expected = (len(study["cases"]) * len(study["gamma"]) + len(extra_points)) \
        * len(study["seeds"])
    assert len(md) == expected
    assert {(r["case"], r["gamma"]) for r in md} == extra_points | {
        (case, g) for case in study["cases"] for g in study["gamma"]}


MD_CONFIG = """[run]
transient_cycles = 120
sampled_cycles = 10
[md]
snapshot_cycles = [125, -1]
[continuum]
field_cycles = [0.0, 1.0]
"""


def write_checkpoint(path, cycle, phase):
    import h5py
    with h5py.File(path, "w") as f:
        f.attrs["schedule_cycle"], f.attrs["schedule_phase"] = cycle, phase


def test_a_stopped_run_continues_from_its_checkpoint_only_before_the_output_it_keeps(work_dir):
    md, continuum = dict(solver="md"), dict(solver="continuum")
    # MD: the sampled cycles from 120 and snapshots at 125 and 129; the continuum: fields from 0
    assert run_module.first_kept_cycle(md, MD_CONFIG) == 120
    assert run_module.first_kept_cycle(continuum, MD_CONFIG) == 0
    checkpoint = os.path.join(work_dir, "md-key.checkpoint.h5")
    assert not run_module.usable_checkpoint(checkpoint, md, MD_CONFIG)   # none yet
    for (cycle, phase), usable in (((60, 3), True), ((120, 0), True), ((120, 1), False),
                                   ((125, 0), False)):
        write_checkpoint(checkpoint, cycle, phase)
        assert run_module.usable_checkpoint(checkpoint, md, MD_CONFIG) is usable
    write_checkpoint(checkpoint, 0, 0)
    assert run_module.usable_checkpoint(checkpoint, continuum, MD_CONFIG)
    write_checkpoint(checkpoint, 1, 0)   # a growth run's fields from cycle 0: start afresh
    assert not run_module.usable_checkpoint(checkpoint, continuum, MD_CONFIG)

    run = dict(solver="md", case_file="case.toml", overrides=["shaker.gamma=1.8"], replicas=1,
               checkpoint_every=10)
    output = os.path.join(work_dir, "md-key.h5")
    write_checkpoint(checkpoint, 60, 3)
    cmd = run_module.solver_command("shaker", run, output, MD_CONFIG, checkpoint)
    assert cmd == ["shaker", "md", "case.toml", "--set", "shaker.gamma=1.8",
                   "--set", f"run.output={output}", "--set", f"run.restart_from={checkpoint}",
                   "--set", f"run.checkpoint={checkpoint}", "--set", "run.checkpoint_every=10"]
    write_checkpoint(checkpoint, 126, 0)   # past the first snapshot: removed, a fresh start
    open(os.path.splitext(checkpoint)[0] + ".previous.h5", "w").close()
    cmd = run_module.solver_command("shaker", run, output, MD_CONFIG, checkpoint)
    assert not any(a.startswith("run.restart_from") for a in cmd)
    assert not os.path.exists(checkpoint)
    assert not os.path.exists(os.path.splitext(checkpoint)[0] + ".previous.h5")
    plain = run_module.solver_command("shaker", dict(run, checkpoint_every=0), output,
                                      MD_CONFIG, checkpoint)
    assert plain == cmd[:7]   # a run that is not resumable writes no checkpoints
    # The sweep's runs are resumable.
    study = sweep.load_sweep(REPOSITORY, "bracket")
    assert {r["checkpoint_every"] for r in sweep.plan_points(REPOSITORY, study)} == {
        sweep.CHECKPOINT_EVERY}


def test_a_stopped_sweep_run_continues_from_its_checkpoint_to_the_straight_runs_result(
        work_dir, shaker):
    # The tiny MD case of the sweep's tests, 44 cycles, run straight in one workdir; in the
    # other an attempt is stopped by SIGTERM once it has checkpointed cycle 1 (as a session's
    # end stops a sweep), well before cycle 40, the first the run keeps, and the sweep
    # continues it.
    import h5py
    overrides = ["shaker.gamma=2.4", "run.seed=1", "layer.particles=300", "md.box_width=16.0",
                 "md.box_depth=8.0", "run.transient_cycles=40", "run.sampled_cycles=4",
                 "md.snapshot_cycles=[40, 41, 42, 43]"]
    run = dict(case="pattern_md_f0p18", solver="md", replicas=1, overrides=overrides,
               case_file=sweep.case_file(REPOSITORY, "pattern_md_f0p18"), timeout=300,
               checkpoint_every=1)
    straight_dir, continued_dir = (os.path.join(work_dir, d) for d in ("straight", "continued"))
    for d in (straight_dir, continued_dir):
        os.makedirs(os.path.join(d, "runs"))
    straight = run_module.execute(shaker, straight_dir, run, rerun=False, reuse_only=False)
    assert straight["status"] == "ok" and "restart_from" not in straight["command"]
    text, key = run_module.run_key(shaker, run)
    stem = os.path.join(continued_dir, "runs", f"md-{key[:20]}")
    checkpoint = stem + ".checkpoint.h5"
    attempt = subprocess.Popen(run_module.solver_command(shaker, run, stem + ".h5", text,
                                                         checkpoint),
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    reached = (0, 0)
    while reached < (2, 0) and attempt.poll() is None:
        try:
            with h5py.File(checkpoint, "r") as f:
                reached = (int(f.attrs["schedule_cycle"]), int(f.attrs["schedule_phase"]))
        except (OSError, KeyError):
            pass
    attempt.send_signal(signal.SIGTERM)
    assert attempt.wait() == 128 + signal.SIGTERM
    assert run_module.usable_checkpoint(checkpoint, run, text)   # stopped before cycle 40
    continued = run_module.execute(shaker, continued_dir, run, rerun=False, reuse_only=False)
    assert continued["status"] == "ok", continued["stderr"]
    assert f"run.restart_from={checkpoint}" in continued["command"]
    assert not os.path.exists(checkpoint)   # a finished run's checkpoints are removed
    with h5py.File(straight["path"]) as a, h5py.File(continued["path"]) as b:
        for name in ("n", "T", "uz"):
            assert np.array_equal(a["profiles"][name][:], b["profiles"][name][:],
                                  equal_nan=True), name   # nan: a bin the layer never reached
    particles = [os.path.splitext(r["path"])[0] + ".particles.h5" for r in (straight, continued)]
    with h5py.File(particles[0]) as a, h5py.File(particles[1]) as b:
        position = "particles/all/position/value"
        assert np.array_equal(a[position][:], b[position][:])
