"""ctest reports.figures: every figure the report generators draw keeps the rules of
granular_shaker/reports/figure_rules.py, on small synthetic inputs (those of the other report
tests, and harness/synthetic_runs.py's cartoon run files).

The functions are enumerated, so that a new figure cannot be forgotten: a report generator
draws a figure only in a function named figure_* that returns it (rc.write_figure writes it;
nothing else in granular_shaker/reports/ or granular_shaker/validation/ calls savefig), and the
figure functions tested here are exactly the figure_* functions of the generators.
"""
import ast
import glob
import inspect
import os
import types

import h5py
import numpy as np
import pytest

from granular_shaker.reports import (figure_rules, make_base_case_report as base,
                                     make_benchmark_report as bench,
                                     make_convergence_report as conv,
                                     make_pattern_report as patterns,
                                     make_sensitivity_report as sens,
                                     make_validation_report as val)

from .. import REPOSITORY, synthetic_runs
from . import test_base_case_report, test_benchmark_report, test_convergence_report

PACKAGE = os.path.dirname(os.path.abspath(figure_rules.__file__))
REPORTS = os.path.join(REPOSITORY, "reports")
GENERATORS = (base, bench, conv, patterns, sens, val)
FIGURE_PREFIX = "figure_"
PYPLOT_DRAWING_CALLS = {"subplots", "figure", "subplot_mosaic", "subplot"}
TABLES = os.path.join(REPORTS, "convergence-tables")


# ---- synthetic inputs ---------------------------------------------------------------------------

SYNTHETIC_CONFIG = """
[shaker]
gamma = 3.0
frequency = 0.095
[layer]
particles = 3937
[material]
e = 0.9
[run]
protocol = "periodic"
phases_per_cycle = 20
transient_cycles = 2
sampled_cycles = 4
[md]
bin_height = 1.0
ceiling = 60.0
box_width = 10.0
replicas = 1
[continuum]
cell_size = 0.5
ceiling = 60.0
"""


def cartoon_profiles(directory, solver, seed):
    """The cartoon run file's profiles (harness/synthetic_runs.py), as the reports
    read them."""
    path = os.path.join(directory, f"{solver}.h5")
    synthetic_runs.write_run(path, SYNTHETIC_CONFIG, solver, seed)
    with h5py.File(path, "r") as f:
        return {k: np.array(f["profiles"][k]) for k in f["profiles"]}


def analysis_of(profiles, solver):
    """A per-phase table and its errors in the shape of `shaker analyze --json`: a shock that
    climbs from the plate between f t 0.12 and 0.34."""
    phase = profiles["phase"]
    com = np.sum(profiles["n"] * profiles["z"], axis=1) / np.sum(profiles["n"], axis=1)
    shocked = (phase >= 0.12) & (phase <= 0.34)
    shock = np.where(shocked, profiles["plate_z"] + 12 * (phase - 0.1), np.nan)
    table = {"phase": phase, "plate_z": profiles["plate_z"], "center_of_mass": com,
             "layer_bottom": com - 5, "layer_top": com + 5, "shock_location": shock,
             "shock_width": np.where(shocked, 1.5, np.nan),
             "max_mach": np.where(shocked, 3 - 5 * (phase - 0.12), 0.5),
             "width_over_mfp": np.where(shocked, 2 + 10 * (phase - 0.12), np.nan)}
    if solver == "continuum":
        table["shock_compressed_top"] = shock - 1
        table["shock_undisturbed_bottom"] = shock + 1
    errors = {k: 0.03 * np.abs(v) for k, v in table.items()} if solver == "md" else None
    return table, errors


def validation_inputs(directory):
    profiles = {s: cartoon_profiles(directory, s, seed) for seed, s in
                enumerate(("md", "continuum"))}
    for name, prof in profiles.items():
        prof["mach"] = np.abs(prof["uz"] - prof["plate_v"][:, None]) / np.sqrt(prof["T"])
    tables = {s: analysis_of(p, s) for s, p in profiles.items()}
    return types.SimpleNamespace(profiles=profiles, tables=tables)


def base_case_inputs(directory):
    test_base_case_report.write_md_run(directory)
    attrs, md = base.read_run(os.path.join(directory, "md.h5"))
    continuum = {k: v for k, v in md.items() if not k.endswith("_se")}
    continuum["nu"] = 1.05 * md["nu"]
    analysis = base.read_analysis(os.path.join(directory, "md-analysis.csv"))
    return {"md": (attrs, md), "continuum": (attrs, continuum)}, \
        {"md": analysis, "continuum": analysis}


def convergence_inputs(directory):
    test_convergence_report.synthetic_study(directory)
    test_convergence_report.synthetic_sampling_study(directory)
    data, _ = conv.read_inputs(directory)
    # And the repository's tables of two studies the review found unfit: 11 quantities of
    # four units in one study, and a time-step study's GCI triples.
    data["errors"] += conv.read_csv(os.path.join(TABLES, "real-3d-minus-1d.errors.csv"),
                                    conv.ERRORS_HEADER)
    data["gci"] += conv.read_csv(os.path.join(TABLES, "real-time-d1-paper-implicit-s2.gci.csv"),
                                 conv.GCI_HEADER)
    return data


def benchmark_runs(directory):
    history = os.path.join(directory, "history")
    work = {"BM_md_collisions": (2.0e6, "collisions_per_second", 2000.0),
            "BM_md_cycle": (3.0e8, "collisions_per_cycle", 5.0e5),
            "BM_continuum_step": (5.0e5, "cell_updates_per_second", 1.0e4)}
    for k in range(3):
        test_benchmark_report.write_run(history, f"2026112{k}T030000Z-{k:012x}", f"{k}" * 40,
                                        work, seed=k)
    return bench.read_history(history)


def sensitivity_inputs(validation):
    variants = [{"name": name, "claims": {"C1": {"value": 0.1 + 0.01 * k},
                                          "C10": {"value": 0.02 * k},
                                          "C15": {"value": None if k == 2 else 0.004 * k}},
                 "mass_gap": {"0": [0.2 * k, 0.05]}}
                for k, name in enumerate(("validation settings", "cell 0.05", "lid 200"))]
    results = {"variants": variants, "md": {"formation_phase": [0.12, 0.004],
                                            "mass_gap": {"0": [0.3, 0.05]}}}
    maps = {}
    for solver, prof in validation.profiles.items():
        maps[solver] = {round(float(p), 6): dict(z=prof["z"][k], nu=prof["nu"][k],
                                                 T=prof["T"][k],
                                                 kn=0.01 / np.maximum(prof["nu"][k], 1e-3))
                        for k, p in enumerate(prof["phase"])}
    phases = list(validation.profiles["md"]["phase"])
    fraction = {"md": {"phase": phases, "fraction": [0.1 + 0.1 * p for p in phases],
                       "fraction_error": [0.02] * len(phases)},
                "continuum": {"phase": phases, "fraction": [0.12 + 0.1 * p for p in phases]}}
    return results, maps, fraction


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    directory = str(tmp_path_factory.mktemp("figure-inputs"))
    for sub in ("validation", "base", "convergence", "benchmark"):
        os.makedirs(os.path.join(directory, sub))
    validation = validation_inputs(os.path.join(directory, "validation"))
    runs, analyses = base_case_inputs(os.path.join(directory, "base"))
    return types.SimpleNamespace(
        validation=validation, base_runs=runs, base_analyses=analyses,
        convergence=convergence_inputs(os.path.join(directory, "convergence")),
        benchmark=benchmark_runs(os.path.join(directory, "benchmark")),
        sensitivity=sensitivity_inputs(validation))


# ---- every figure function, on its inputs ------------------------------------------------------

def validation_figures(name):
    def make(i):
        v = i.validation
        md, co = v.tables["md"], v.tables["continuum"]
        runs = {s: (v.profiles[s], v.tables[s][0]) for s in v.profiles}
        return {
            "figure_profiles": lambda: [val.figure_profiles(runs)],
            "figure_single_shock": lambda: [val.figure_single_shock(
                [("e = 0.99", v.profiles["continuum"], {"continuum": co, "md": md}),
                 ("e = 0.90", None, {"md": md})])],
            "figure_mach": lambda: [val.figure_mach({s: (v.profiles[s], *v.tables[s])
                                                     for s in v.profiles})],
            "figure_mach_width": lambda: [val.figure_mach_width(v.tables)],
            "figure_shock_speed": lambda: [val.figure_shock_speed(
                {"md": [(0.85, 1.2, 0.1), (0.9, 1.5, None), (0.99, 2.0, 0.2)],
                 "continuum": [(0.85, 1.1, None), (0.99, 1.9, None)]})],
            "figure_restitution": lambda: [val.figure_restitution(
                [("constant e = 0.9", *md), ("e(v_n)", *md)])],
            "figure_depths": lambda: [val.figure_depths(
                [(h, s, *v.tables[s]) for h in ("H = 4.5", "H = 9") for s in v.tables])],
        }[name]()
    return make


def convergence_figures(name):
    def make(i):
        data = i.convergence
        series = conv.series_of(data["errors"])
        by_study = {}
        for table in ("gci", "sampling"):
            for r in data[table]:
                by_study.setdefault((table, r["study"]), []).append(r)
        return {
            "figure_errors": lambda: [conv.figure_errors(
                study, series[study], {r["design_order"] for r in data["orders"]
                                       if r["study"] == study}) for study in sorted(series)],
            "figure_gci": lambda: [conv.figure_gci(study, rows) for (table, study), rows
                                   in sorted(by_study.items()) if table == "gci"],
            "figure_sampling": lambda: [conv.figure_sampling(study, rows) for (table, study), rows
                                        in sorted(by_study.items()) if table == "sampling"],
        }[name]()
    return make


def pattern_views():
    """Pattern sweep results whose points carry views: MD stripes of mode 6 from Gamma 2.2,
    the continuum growing from Gamma 3 (granular_shaker.patterns.views)."""
    x = np.arange(64) * 2.0

    def view(amplitude, cells, frames):
        field = amplitude * np.cos(2 * np.pi * 6 * x / 128.0)[:, None] * np.ones((1, cells))
        power = [1e-4] * 5 + [amplitude ** 2 / 4] + [1e-4] * 10
        return dict(box=[128.0, 2.0 * cells], cycle=129.0, spectrum_phase=0.0, frames=frames,
                    power=power, power_error=[p / 10 for p in power] if frames > 1 else
                    [None] * 16, fields={"0": field.tolist(), "0.5": (-0.3 * field).tolist()})

    md = [dict(gamma=g, order=o, order_error=0.02, a2=1.0, half_wavelength_correlation=c,
               wavelength=w, view=view(a, 4, 10)) for g, o, c, w, a in
          zip((2.0, 2.1, 2.2, 2.6), (0.6, 0.7, 1.2, 1.9), (0.0, 0.2, 0.7, 0.8),
              (42.0, 40.0, 21.2, 21.3), (0.05, 0.06, 0.3, 0.5))]
    continuum = [dict(gamma=g, rate=r, rate_error=0.01, mode=6, mode_wavelength=21.33,
                      view=view(a, 2, 1)) for g, r, a in
                 zip((2.6, 3.0, 3.4), (-0.1, -0.01, 0.06), (1e-5, 1e-4, 1e-3))]
    return {"pattern_md_f0p18": dict(solver="md", points=md, onset=dict(reason="none")),
            "pattern_continuum_f0p18": dict(solver="continuum", points=continuum,
                                            onset=dict(gamma_c=3.05, gamma_c_error=0.05))}


def with_seed_spectra(cases):
    """The MD points' spectra over two seeds at phase 0: their views' spectra, errors doubled."""
    for point in cases["pattern_md_f0p18"]["points"]:
        point.update(seeds=2, mode_power={"0": point["view"]["power"]},
                     mode_power_error={"0": [2 * e for e in point["view"]["power_error"]]})
    return cases


FIGURE_CASES = {
    **{f"make_validation_report.{n}": validation_figures(n) for n in (
        "figure_profiles", "figure_single_shock", "figure_mach", "figure_mach_width",
        "figure_shock_speed", "figure_restitution", "figure_depths")},
    **{f"make_convergence_report.{n}": convergence_figures(n) for n in (
        "figure_errors", "figure_gci", "figure_sampling")},
    "make_base_case_report.figure_profiles": lambda i: [base.figure_profiles(i.base_runs)],
    "make_base_case_report.figure_trajectories":
        lambda i: [base.figure_trajectories(i.base_analyses)],
    "make_benchmark_report.figure_history": lambda i: [
        bench.figure_history(i.benchmark, bench.throughput_series(i.benchmark)),
        bench.figure_history(i.benchmark[1:2], {})],
    "make_pattern_report.figure_order_parameter": lambda i: [patterns.figure_order_parameter({
        "pattern_md_f0p18": {"points": [dict(gamma=g, order=m, order_error=0.02) for g, m in
                                        zip((2.0, 2.4, 2.8, 3.2), (0.3, 0.32, 0.6, 0.8))],
                             "onset": dict(gamma_c=2.5, floor=0.09, slope=0.6)},
        "pattern_md_f0p14": {"points": [dict(gamma=g, order=0.3, order_error=0.02)
                                        for g in (2.0, 2.4, 2.8, 3.2)],
                             "onset": dict(reason="no onset")}}),
        patterns.figure_order_parameter({"pattern_md_f0p18": {
            "points": [dict(gamma=g, order=m, order_error=0.02, a2=1.0,
                            half_wavelength_correlation=c) for g, m, c in
                       zip((2.0, 2.1, 2.2, 2.4), (0.6, 0.7, 1.2, 1.8), (0.0, 0.2, 0.7, 0.8))],
            "onset": dict(reason="the best onset is at the end of the sweep")}})],
    "make_pattern_report.figure_critical_mode": lambda i: [patterns.figure_critical_mode({
        "pattern_md_f0p18": {"solver": "md", "points": [
            dict(gamma=g, mode_power={"0": [1e-4] * 5 + [p]}, mode_power_error={"0": [1e-5] * 6})
            for g, p in zip((1.9, 2.0, 2.1, 2.2, 2.4), (2e-4, 3e-4, 5e-4, 1e-2, 4e-2))],
            "swift_hohenberg": dict(mode=6, phase="0", below=2.2, gamma_mf=2.2, floor=1e-4,
                                    strength=2e-5)},
        "pattern_md_f0p14": {"solver": "md", "points": [
            dict(gamma=g, mode_power={"0": [1e-4] * 4 + [p]}, mode_power_error={"0": [1e-5] * 5})
            for g, p in zip((1.9, 2.0, 2.2), (3e-4, 5e-2, 8e-2))],
            "swift_hohenberg": dict(mode=5, phase="0", below=2.0, reason="too few points")}})],
    "make_pattern_report.figure_growth_rate": lambda i: [patterns.figure_growth_rate({
        "pattern_continuum_f0p18": {"points": [dict(gamma=g, rate=r, rate_error=0.02) for g, r in
                                               zip((2.2, 3.0, 3.8, 4.2), (-0.2, -0.1, 0.06, -0.1))],
                                    "onset": dict(gamma_c=3.5, gamma_c_error=0.07)},
        "pattern_continuum_f0p14": {"points": [dict(gamma=g, rate=-0.2, rate_error=0.02)
                                               for g in (2.2, 3.0, 3.8, 4.2)],
                                    "onset": dict(reason="no change of sign")}})],
    "make_pattern_report.figure_top_views": lambda i: [
        patterns.figure_top_views(pattern_views()),
        patterns.figure_top_views({"pattern_md_f0p18": pattern_views()["pattern_md_f0p18"]})],
    "make_pattern_report.figure_spectra": lambda i: [
        patterns.figure_spectra(pattern_views()),
        patterns.figure_spectra(with_seed_spectra(pattern_views()))],
    "make_pattern_report.figure_wavelength": lambda i: [patterns.figure_wavelength(
        pattern_views(), {"pattern_md_f0p18": (0.18, 5.0), "pattern_continuum_f0p18": (0.18, 5.0)},
        dict(offset=1.0, amplitude=1.1, exponent=1.32))],
    "make_sensitivity_report.figure_variants":
        lambda i: [sens.figure_variants(i.sensitivity[0])],
    "make_sensitivity_report.figure_knudsen_maps":
        lambda i: [sens.figure_knudsen_maps(i.sensitivity[1])],
    "make_sensitivity_report.figure_knudsen_fraction":
        lambda i: [sens.figure_knudsen_fraction(i.sensitivity[2])],
}


@pytest.mark.parametrize("name", sorted(FIGURE_CASES))
def test_figure_keeps_the_rules(name, inputs):
    import matplotlib.pyplot as plt
    figures = FIGURE_CASES[name](inputs)
    assert figures, f"{name}: no figure made"
    for number, fig in enumerate(figures):
        problems = figure_rules.figure_problems(fig)
        plt.close(fig)
        print(f"{name} [{number}]: {len(problems)} problems")
        assert problems == [], f"{name} [{number}]:\n" + "\n".join(problems)


# ---- the enumeration ---------------------------------------------------------------------------

def test_every_figure_function_is_tested():
    functions = {f"{m.__name__.split('.')[-1]}.{name}" for m in GENERATORS
                 for name, f in inspect.getmembers(m, inspect.isfunction)
                 if name.startswith(FIGURE_PREFIX) and f.__module__ == m.__name__}
    assert functions == set(FIGURE_CASES), \
        f"untested: {sorted(functions - set(FIGURE_CASES))}; " \
        f"not figure functions: {sorted(set(FIGURE_CASES) - functions)}"


def python_sources():
    """The harness's modules: the report generators and the validation study."""
    return sorted(glob.glob(os.path.join(PACKAGE, "*.py"))
                  + glob.glob(os.path.join(os.path.dirname(PACKAGE), "validation", "*.py")))


def test_figures_are_drawn_only_in_figure_functions():
    """A function that creates a figure is named figure_*; savefig is called only by
    report_common.save_figure_atomically; every module that imports matplotlib is a
    generator tested here (or the rules themselves)."""
    offenders, drawing_modules = [], set()
    for path in python_sources():
        tree = ast.parse(open(path).read(), path)
        module = os.path.splitext(os.path.basename(path))[0]
        for function in [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)]:
            for call in [n for n in ast.walk(function) if isinstance(n, ast.Call)]:
                called = getattr(call.func, "attr", getattr(call.func, "id", ""))
                on = getattr(getattr(call.func, "value", None), "id", None)
                creates = (on == "plt" and called in PYPLOT_DRAWING_CALLS) or called == "Figure"
                if creates and not function.name.startswith(FIGURE_PREFIX):
                    offenders.append(f"{module}.{function.name} creates a figure")
                if called == "savefig" and function.name != "save_figure_atomically":
                    offenders.append(f"{module}.{function.name} calls savefig")
                if creates:
                    drawing_modules.add(module)
    assert offenders == [], "\n".join(offenders)
    tested = {m.__name__.split(".")[-1] for m in GENERATORS}
    assert drawing_modules == tested, \
        f"modules drawing figures {sorted(drawing_modules)} against tested {sorted(tested)}"
