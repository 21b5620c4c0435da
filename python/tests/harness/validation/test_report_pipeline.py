"""ctest validation.report_pipeline: the whole validation pipeline on synthetic run files,
without the solvers.

synthetic_runs.py writes cartoon run files (docs/output-schema.md) under the names the runner
reuses; the validation study (--reuse-only) then analyses them with the real `shaker analyze` and
`shaker compare`, analyses the single-shock ensembles, evaluates every claim and writes the report.
Checks: every claim id C1..C20 in the claims table, pass, FAIL and "not measured" marks all
present, the seven figure PNGs exist and are non-empty, no run was re-simulated, values the
cartoon fixes exactly (per cycle above z = 80: crossings 0.3 and 5, distinct particles 0.8 x those;
the collapse detected from the recorded exit status) come out exactly, the continuum GCI of a
synthetic grid-study table reaches the claims table (C6) or its absence is said (C5), every
table gives units (header or units column; those the report declares for `shaker analyze`
quantities are the ones its --json prints), and --require sets the exit status (0 for a
passing claim, 1 for a failing one).

    python3 -m pytest python/tests/harness/validation/test_report_pipeline.py --shaker SHAKER
"""
import json
import os
import re
import subprocess

import pytest

from granular_shaker.reports import report_common
from granular_shaker.validation import quantities

from .. import harness_command, package_environment, synthetic_runs
CASES = ("base,single_shock_e0p99,single_shock_e0p90,single_shock_e0p85,velocity_dependent,"
         "depth_h4p5,depth_h13p5,collapse_e0p70")
FIGURES = ("fig1-profiles.png", "fig2-single-shock.png", "fig3-mach.png", "fig4-mach-width.png",
           "fig5-shock-speed.png", "fig6-restitution-models.png", "fig7-depths.png")


GCI_HEADER = ("study,quantity,h1,h2,h3,phi1,phi2,phi3,order,phi_extrapolated,"
              "relative_difference21,extrapolated_error21,gci21,gci32,convergence,"
              "design_order,order_tolerance,uncertainty1,pass")


def write_gci_table(path):
    """A grid uncertainty of 2 % for C6's quantity at every cell size the quick cases might
    use, and no row for C5's, so the report must show one uncertainty and say why the other
    is missing."""
    with open(path, "w") as f:
        f.write(GCI_HEADER + "\n")
        for h in (0.05, 0.1, 0.2, 0.25, 0.4, 0.5, 1.0):
            f.write(f"synthetic,max_mach_ft0.08-0.13,{h},{2 * h},{4 * h},11,11.1,11.3,2,10.97,"
                    "0.009,0.003,0.02,0.04,monotonic,2,0.1,0.22,1\n")


def run_validation(shaker, workdir, report, require, gci):
    cmd = harness_command("validation", "--shaker", shaker,
                          "--workdir", workdir, "--report", report, "--cases", CASES, "--quick",
                          "--reuse-only", "--require", require, "--gci", gci)
    result = subprocess.run(cmd, capture_output=True, text=True, env=package_environment())
    return result.returncode, result.stdout + result.stderr


def test_report_pipeline(shaker, work_dir):
    tmp = work_dir
    workdir, report = os.path.join(tmp, "work"), os.path.join(tmp, "validation.md")
    synthetic_runs.write_runs(shaker, workdir, CASES, quick=True)

    gci = os.path.join(tmp, "real-1d-base.gci.csv")
    write_gci_table(gci)
    rc, output = run_validation(shaker, workdir, report, "C18", gci)
    assert rc == 0, f"--require C18 (a passing claim) exits 0 (got {rc})" + (
        f"\n{output}" if rc not in (0, 1) else "")
    text = open(report).read() if os.path.exists(report) else ""
    rows = {m.group(1): m.group(0) for m in re.finditer(r"^\| (C\d+) \|.*$", text, re.M)}
    assert sorted(rows, key=lambda i: int(i[1:])) == [f"C{n}" for n in range(1, 21)], \
        f"claims table has rows C1..C20 (found {sorted(rows)})"
    assert any(r.endswith("| pass |") for r in rows.values()), "some claim is marked pass"
    assert any(r.endswith("| **FAIL** |") for r in rows.values()), "some claim is marked FAIL"
    assert "not measured" in rows.get("C15", ""), \
        "C15 (its continuum_ceiling200 runs absent) is reported as not measured"
    for name in FIGURES:
        path = os.path.join(tmp, "validation", name)
        assert os.path.exists(path) and os.path.getsize(path) > 10000, \
            f"{name} exists ({os.path.getsize(path) if os.path.exists(path) else 0} bytes)"
    for n in range(1, 8):
        assert f"## Fig. {n}:" in text, f"section for Fig. {n}"
    assert "## Agreement metrics" in text and "center_of_mass_fractional_rms" in text, \
        "agreement metrics table"

    results = json.load(open(os.path.join(workdir, "results.json")))
    assert all(r["reused"] for r in results["runs"]), "every run reused, none re-simulated"
    claims = {c["id"]: c for c in results["claims"]}

    def value(claim, solver, check=0):
        return claims[claim]["per_solver"][solver]["checks"][check]["value"]

    # Check 0: distinct particles (particles_z80), check 1: upward crossings (crossings_z80).
    for claim, crossings in (("C17", 0.3), ("C20", 5.0)):
        for check, expected, what in ((0, 0.8 * crossings, "distinct particles"),
                                      (1, crossings, "upward crossings")):
            got = value(claim, "md", check)
            assert abs(got - expected) < 1e-9, \
                f"{claim} {what} per cycle above 80 = {got} (cartoon: {expected:g})"
    assert claims["C18"]["status"] == "pass" and value("C18", "md") == 1.0, \
        "C18: collapse detected from the recorded exit status"
    c10 = value("C10", "md_vs_continuum")
    assert c10 is not None and 0 < c10 < 0.03, f"C10 centre-of-mass fractional RMS {c10}"
    md_c13 = claims["C13"]["per_solver"]["md"]["status"]
    assert md_c13 == "not measured", f"C13 without the e = 0.80 runs: {md_c13}"
    assert claims["C14"]["per_solver"]["md"]["checks"][0].get("error") is not None, \
        "C14 has a jackknife error from the ensemble's replicas"

    check_numbers_are_shaker_analyze(shaker, results, value, tmp)
    check_collision_rates(results)

    # Columns of the claims table: id, claim, units, paper, MD, continuum, band, result.
    c6, c5 = rows.get("C6", "").split(" | "), rows.get("C5", "").split(" | ")
    c6_continuum = c6[5] if len(c6) > 5 else ""
    shown = re.search(r"([0-9.eE+-]+) ± ([0-9.eE+-]+) \(grid 2 %", c6_continuum)
    assert (shown is not None and abs(float(shown.group(2)) - 0.02 * abs(float(shown.group(1))))
            <= 0.01 * abs(float(shown.group(1)))), \
        f"C6 continuum value carries its grid uncertainty, 2 % of the value: '{c6_continuum}'"
    assert len(c5) > 5 and "no shock_width_ft0.22 row" in c5[5], \
        f"C5 says its GCI row is missing: '{c5[5] if len(c5) > 5 else ''}'"
    assert "grid" not in (c6[4] if len(c6) > 4 else "grid"), \
        "the MD value carries no grid uncertainty"
    check_units(text, rows, claims, tmp)
    check_missing_units_are_refused(os.path.join(workdir, "results.json"), tmp)

    rc, _ = run_validation(shaker, workdir, report, "C3", gci)
    assert rc == 1, f"--require C3 (failing on the cartoon) exits 1 (got {rc})"


def check_numbers_are_shaker_analyze(shaker, results, value, tmp):
    """The report's numbers are those `shaker analyze` prints: it runs again, by hand, on the
    single-shock ensemble of e = 0.9 and on the base case (its JSON stays in `tmp`), and its
    values are compared with the claims' (`value(claim, solver)`)."""
    for claim, solver, case, name in (("C4", "md", "base", "exit_phase"),
                                      ("C1", "md", "base", "formation_phase"),
                                      ("C14", "md", "single_shock_e0p90", None)):
        view = results["views"].get(f"{case}/{solver}")
        if not view or not view.get("path"):
            pytest.fail(f"{case}/{solver} has no run file")
        out = os.path.join(tmp, f"again-{case}.json")
        subprocess.run([shaker, "analyze", view["path"], "--json", out, "--quiet"], check=True)
        per_run = json.load(open(out))["per_run"]
        if name:
            assert per_run[name]["value"] == value(claim, solver), (
                f"{claim}: report {value(claim, solver)} = shaker analyze {name} "
                f"{per_run[name]['value']}")
        else:
            assert per_run["shock_speed"]["value"] == view["shock_speed"], (
                f"{case}: report shock speed {view['shock_speed']} = shaker analyze "
                f"{per_run['shock_speed']['value']}")


def check_collision_rates(results):
    """Every MD view's collisions per second: the run files' running totals over the runs'
    seconds."""
    md_views = [v for v in results["views"].values() if v["solver"] == "md" and v["status"] == "ok"]
    for view in md_views:
        seconds = sum(r["seconds"] for r in results["runs"] if r["case"] == view["case"]
                      and r["solver"] == "md" and r["status"] == "ok")
        runs = sum(1 for r in results["runs"] if r["case"] == view["case"] and r["solver"] == "md"
                   and r["status"] == "ok")
        expected = runs * synthetic_runs.SYNTHETIC_COLLISIONS / seconds
        rate = view["collisions_per_second"]
        assert rate is not None and abs(rate - expected) <= 1e-9 * expected, (
            f"{view['case']}: MD collisions per second from the run files' running totals "
            f"{rate} (cartoon: {expected})")
    assert len(md_views) > 0, f"MD views with a collision rate: {len(md_views)}"


def check_units(text, rows, claims, tmp):
    """Every table of the report gives units: in the header of a column that holds one
    quantity, in a units column where the rows hold different quantities."""
    lines = text.splitlines()
    assert "| id | claim | units | paper | MD | continuum | band | result |" in lines, \
        "claims table without its units column"
    for claim_id, claim in claims.items():
        cells = rows.get(claim_id, "").split(" | ")
        expected = "; ".join(quantities.UNITS[c["quantity"]] for c in claim["checks"])
        assert len(cells) > 2 and cells[2] == expected, \
            f"{claim_id}: units '{cells[2] if len(cells) > 2 else ''}', expected '{expected}'"
    assert rows["C5"].split(" | ")[2] == "sigma" and rows["C17"].split(" | ")[2] == "1; 1", \
        "C5 (a width) in sigma, C17 (two counts per cycle) in 1; 1"
    for header in ("| case | solver | replicas | status | seconds [s] | reused | program |",
                   "| f t [1] | solver | plate z [sigma] | layer bottom [sigma] | "
                   "layer top [sigma] | shock location [sigma] | width d [sigma] |",
                   "| case | solver | formation f t [1] | shock speed [sqrt(g sigma)] | "
                   "centre-of-mass apex [sigma] |",
                   "| solver | f t [1] | shock location [sigma] | maximum Ma in the layer [1] |",
                   "| e [1] | MD v_shock [sqrt(g sigma)] | continuum v_shock [sqrt(g sigma)] |",
                   "| restitution | shock speed [sqrt(g sigma)] | centre-of-mass apex [sigma] |",
                   "| H [sigma] | solver | mean centre of mass [sigma] | formation f t [1] | "
                   "shock speed [sqrt(g sigma)] |"):
        assert header in lines, f"table header with units missing: {header}"
    fig4 = next((line for line in lines if line.startswith("| f t [1] | md max Ma")), "")
    assert "| md max Ma [1] | md d/xi [1] |" in fig4, f"Fig. 4 header without units: '{fig4}'"
    evidence = [line for line in lines if line.startswith("| evidence |")]
    assert evidence and all(line.startswith("| evidence | units |") for line in evidence), \
        f"evidence tables without a units column: {evidence}"
    metric = next((line for line in lines if line.startswith("| metric |")), "")
    assert metric.startswith("| metric | units |"), f"metrics table without units: '{metric}'"
    for name, units in (("center_of_mass_absolute_rms", "sigma"),
                        ("center_of_mass_fractional_rms", "1"), ("T_l1_mean_over_phases",
                                                                 "g sigma")):
        assert any(line.startswith(f"| {name} | {units} | ") for line in lines), \
            f"metric {name} without its units {units}"
    # The units the reports declare for `shaker analyze` quantities are those it prints.
    analysis = json.load(open(os.path.join(tmp, "again-base.json")))
    printed = {name: q["unit"] for part in ("per_phase", "per_run")
               for name, q in analysis[part].items()}
    for name, units in report_common.ANALYSIS_UNITS.items():
        assert printed.get(name) == units, \
            f"{name}: reports declare [{units}], shaker analyze --json prints {printed.get(name)}"


def check_missing_units_are_refused(results_path, tmp):
    """A claim's check or a metric without units in results.json is an error of the report
    generator (exit 2, naming it), not a blank cell."""
    for what, remove in (("claim", lambda r: r["claims"][0]["checks"][0].pop("units")),
                         ("metric", lambda r: r["metric_units"].pop(
                             "center_of_mass_absolute_rms"))):
        results = json.load(open(results_path))
        remove(results)
        broken = os.path.join(tmp, f"results-without-{what}-units.json")
        json.dump(results, open(broken, "w"))
        report = os.path.join(tmp, f"without-{what}-units.md")
        result = subprocess.run(harness_command("reports.make_validation_report", "--results",
                                                broken, "--output", report),
                                capture_output=True, text=True, env=package_environment())
        assert result.returncode == 2 and "no units" in result.stderr \
            and not os.path.exists(report), \
            f"{what} without units: exit {result.returncode}, {result.stderr.strip()[-300:]}"
