"""ctest reports.convergence_report: granular_shaker.reports.make_convergence_report on a small
synthetic study in a temporary directory.

Checks the provenance header, the order and GCI rows with
their pass/fail marks, the failure summary with measured values, the units of every table
(in a column's header, or in a units column where the rows hold different quantities; a name
without declared units is refused), the PNG plot, --strict, and bad input; and the MD sampling
section (slope fits against K^-1/2, the se table, its plot, the
bin-size checks) on a synthetic sampling study; and the term-share tables of the
manufactured sources; and the GCI figures (one per study, linked below the GCI table, removed
with their study).

The report is tested against the one judge, the `pass` column the C++ side writes: for every
row of every table it reads (the synthetic ones and the repository's convergence-tables/), the
mark shown must be that column's, and the summary must count those marks. Rows whose numbers
lie outside the band but whose pass column says 1 (and one inside the band that says 0) must
be shown as the column says: the report does not second-guess the judge.
"""
import csv
import glob
import math
import os
import re
import shutil
import subprocess

import numpy as np

from granular_shaker.reports import make_convergence_report, report_common

from .. import REPOSITORY, harness_command, package_environment

REPORTS = os.path.join(REPOSITORY, "reports")
ORDERS_HEADER = ("study,field,norm,fit_points,fitted_order,order_std_error,pair_order_finest,"
                 "pair_order_next,design_order,tolerance,pass")
GCI_HEADER = ("study,quantity,h1,h2,h3,phi1,phi2,phi3,order,phi_extrapolated,"
              "relative_difference21,extrapolated_error21,gci21,gci32,convergence,"
              "design_order,order_tolerance,uncertainty1,pass")
BOUNDS_HEADER = "study,quantity,value,value_basis,bound,bound_basis,pass"


def write(path, header, rows):
    with open(path, "w") as f:
        f.write(header + "\n")
        for row in rows:
            f.write(",".join(str(x) for x in row) + "\n")


def synthetic_study(directory):
    study = "synthetic-1d-space"
    h = [0.1 / 2 ** k for k in range(4)]
    models = {"n": lambda x: 0.5 * x * x * (1 + 0.1 * x),
              "uz": lambda x: 2.0 * x * x * (1 - 0.2 * x),
              "T": lambda x: 0.3 * x}  # first order: must fail the second-order band
    scale = {"L1": 1.0, "L2": 1.3, "Linf": 2.1}
    errors, orders = [], []
    for field, model in models.items():
        for norm, s in scale.items():
            e = [s * model(x) for x in h]
            for level, (x, err) in enumerate(zip(h, e)):
                errors.append((study, field, norm, level, repr(x), repr(err)))
            slope, _ = np.polyfit(np.log(h[1:]), np.log(e[1:]), 1)
            pairs = [math.log(e[k] / e[k + 1]) / math.log(2.0) for k in range(3)]
            in_band = all(abs(p - 2.0) <= 0.1 for p in (slope, pairs[2], pairs[1]))
            # The judge's word differs from the band twice: the report must show its word.
            claimed = {("T", "L2"): 1, ("uz", "Linf"): 0}.get((field, norm), int(in_band))
            orders.append((study, field, norm, 3, repr(slope), "0.001", repr(pairs[2]),
                           repr(pairs[1]), "2", "0.1", claimed))
    write(os.path.join(directory, "synthetic.errors.csv"), "study,field,norm,level,h,error", errors)
    write(os.path.join(directory, "synthetic.orders.csv"), ORDERS_HEADER, orders)
    phi = [2.0 + 0.3 * x * x for x in (0.025, 0.05, 0.1)]
    e21 = abs(phi[0] - phi[1]) / phi[0]
    gci21 = 1.25 * e21 / 3.0
    gci32 = 1.25 * abs(phi[1] - phi[2]) / phi[1] / 3.0
    write(os.path.join(directory, "qoi.gci.csv"), GCI_HEADER, [
        ("base-1d", "shock_location", 0.025, 0.05, 0.1, *phi, 2.0, 2.0, e21, 0.0, gci21, gci32,
         "monotonic", 2, 0.1, phi[0] * gci21, 1),
        ("base-1d", "max_mach", 0.025, 0.05, 0.1, 3.1, 3.0, 3.3, 1.5, 3.2, 0.032, 0.03, 0.05,
         0.4, "oscillatory", 2, 0.1, 0.15, 0),
        ("base-3d", "shock_location", 0.5, 1.0, "nan", 1.01, 1.04, "nan", 2.0, 1.0, 0.0297, 0.01,
         0.0297, "nan", "two-grids", 2, "nan", 0.03, "nan"),
        # A time-step study's row: its order is a diagnostic (the claim is its bound check).
        ("real-time-x", "max_mach", 0.25, 0.5, 1.0, 3.1, 3.0, 3.3, 1.5, 3.2, 0.032, 0.03, 0.05,
         0.4, "oscillatory", 2, 0.1, 0.15, "nan")])
    write(os.path.join(directory, "qoi.bounds.csv"), BOUNDS_HEADER, [
        ("real-time-x", "max_mach", 0.001, "time error of the production step (largest change)",
         0.002, "grid uncertainty at cell 0.1 (finest of 0.4/0.2/0.1)", 1),
        ("real-time-x", "shock_speed", 0.005, "time error of the production step (extrapolated)",
         0.002, "grid uncertainty at cell 0.1 (finest of 0.4/0.2/0.1)", 0),
        ("real-time-x", "front_width_over_mfp_ft0.22", 0.004, "time error of the production step "
         "(largest change)", "nan", "none: the coarse column does not resolve it", "nan")])


def synthetic_sampling_study(directory):
    """Standard errors of independent cycles (se ~ K^-1/2) and of drifting ones (flat)."""
    study = "synthetic-md-sampling"
    ks = [2, 4, 8, 16]
    se_rows, fit_rows = [], []
    for quantity, phase, exponent in (("T_se_layer_rms", "0.22", -0.5),
                                      ("center_of_mass", "0.5", 0.05),  # must fail
                                      ("n_se_layer_rms", "nan", -0.5)):
        se = [0.3 * k ** exponent for k in ks]
        for k, e in zip(ks, se):
            se_rows.append((study, quantity, phase, k, 16 // k, (16 // k) * (k - 1), k, 0, repr(e)))
        slope = np.polyfit(np.log(ks), np.log(se), 1)[0]
        claimed = 1 if quantity == "n_se_layer_rms" else int(abs(slope + 0.5) <= 0.42)
        if quantity == "n_se_layer_rms":
            slope = -0.95  # outside -0.5 ± 0.42, yet the judge's column says pass
        fit_rows.append((study, quantity, phase, 4, repr(slope), "0.01", "-0.5", "0.42", claimed))
    write(os.path.join(directory, "md.sampling.csv"),
          "study,quantity,phase,K,blocks,degrees_of_freedom,effective_K,missing,standard_error",
          se_rows)
    write(os.path.join(directory, "md.sampling-fit.csv"),
          "study,quantity,phase,fit_points,fitted_slope,slope_std_error,expected_slope,band,pass",
          fit_rows)
    write(os.path.join(directory, "md.bin-size.csv"),
          "study,quantity,phase,sigma_value,half_sigma_value,statistic,value,criterion,limit,"
          "pass", [
              (study, "T", 0.22, "nan", "nan", "fraction of layer bins within 2 combined se", 0.96,
               "at_least", 0.9, 1),
              (study, "uz", 0.22, "nan", "nan", "fraction of layer bins within 2 combined se", 0.8,
               "at_least", 0.9, 0),
              (study, "shock_location", 0.22, 17.0, 17.5, "shift", 0.5, "at_most", 1.1, 1)])


def is_png(path, min_size=5000):
    return (os.path.exists(path) and open(path, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
            and os.path.getsize(path) > min_size)


def run(*args):
    """The report made as users make it: its command run in a process of its own."""
    return subprocess.run(harness_command("reports.make_convergence_report", *args),
                          capture_output=True, text=True, env=package_environment())


def line_with(text, *fragments):
    for line in text.splitlines():
        if all(f in line for f in fragments):
            return line
    return ""


# Where the report shows each table that carries the judge's pass column, and the columns that
# name one of its rows there (phase is shown as PHASE_COLUMN).
JUDGED_TABLES = {
    "orders": ("## Observed orders against the design order", ("study", "field", "norm")),
    "gci": ("## Grid convergence index of the quantities of interest", ("study", "quantity")),
    "sampling-fit": ("## MD sampling convergence", ("study", "quantity", "phase")),
    "bin-size": ("### Bin size: sigma against sigma/2", ("study", "quantity", "phase")),
    "bounds": ("## Errors within their uncertainty", ("study", "quantity")),
}
# Only a GCI mark carries a note: its order band, or why a row is not checked.
NOTED_TABLES = {"gci"}
PHASE_COLUMN = "f t [1]"


def table_cells(line):
    """The cells of a markdown table line; an escaped '\\|' stays inside its cell."""
    cells = re.split(r"(?<!\\)\|", line.strip().strip("|"))
    return [cell.strip().replace("\\|", "|") for cell in cells]


def markdown_tables(text):
    """{heading: rows of the first table under it, each a dict keyed by the table's header}."""
    tables, heading, lines = {}, None, text.splitlines()
    for number, line in enumerate(lines):
        if line.startswith("#"):
            heading = line
            continue
        starts_table = line.startswith("|") and lines[number + 1:number + 2] != [] \
            and lines[number + 1].startswith("|---")
        if starts_table and heading not in tables:
            header = table_cells(line)
            body = []
            for row_line in lines[number + 2:]:
                if not row_line.startswith("|"):
                    break
                body.append(dict(zip(header, table_cells(row_line))))
            tables[heading] = body
    return tables


def shown_phase_is(shown, phase_cell):
    phase = float(phase_cell)
    if math.isnan(phase):
        return shown == "all"
    try:
        return math.isclose(float(shown), phase, rel_tol=1e-3)  # shown to 3 digits
    except ValueError:
        return False


def names_row(shown, row, key_columns):
    return all(shown_phase_is(shown.get(PHASE_COLUMN, ""), row["phase"]) if column == "phase"
               else shown.get(column) == row[column] for column in key_columns)


def mark_of_pass_column(cell):
    value = float(cell)
    if math.isnan(value):
        return "not checked"
    return "PASS" if value == 1 else "**FAIL**"


def csv_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def shows_mark(result, expected, kind):
    return result == expected or (kind in NOTED_TABLES and result.startswith(expected + " ("))


def failure_list(text):
    lines = text.splitlines()
    if "Failing checks (measured values):" not in lines:
        return []
    start = lines.index("Failing checks (measured values):") + 2
    listed = []
    for line in lines[start:]:
        if not line.startswith("- "):
            break
        listed.append(line)
    return listed


def check_marks_follow_the_judge(input_dir, text, label):
    """Every row of every judged table under input_dir is shown exactly once, with the mark of
    its pass column; the summary and the failure list count those marks. Returns the number of
    rows compared."""
    tables = markdown_tables(text)
    checks = failed = compared = 0
    for kind, (heading, key_columns) in JUDGED_TABLES.items():
        shown_rows = tables.get(heading, [])
        paths = sorted(glob.glob(os.path.join(input_dir, "**", f"*.{kind}.csv"), recursive=True))
        # A former judge's bound tables are shown apart, not as checks (test below).
        rows = [row for path in paths for row in csv_rows(path)
                if make_convergence_report.AWAITING_RERUN not in path.split(os.sep)]
        if rows:
            assert len(shown_rows) == len(rows), \
                f"{label}: {len(shown_rows)} rows shown under '{heading}', {len(rows)} in tables"
        for row in rows:
            expected = mark_of_pass_column(row["pass"])
            checks += expected != "not checked"
            failed += expected == "**FAIL**"
            name = f"{label}: {kind} " + " / ".join(row[column] for column in key_columns)
            matches = [shown for shown in shown_rows if names_row(shown, row, key_columns)]
            assert len(matches) == 1, f"{name} shown {len(matches)} times"
            if len(matches) == 1:
                result = matches[0].get("result", "")
                assert shows_mark(result, expected, kind), \
                    f"{name}: shown '{result}', its pass column says {row['pass']}"
                compared += 1
    assert f"{checks} checks: {checks - failed} pass, {failed} fail." in text, \
        f"{label}: summary does not count the pass columns ({checks} checks, {failed} fail)"
    assert len(failure_list(text)) == failed, \
        f"{label}: {len(failure_list(text))} failing checks listed, pass columns say {failed}"
    return compared


def test_report_on_a_synthetic_study(work_dir):
    work = work_dir
    inputs = os.path.join(work, "input")
    os.makedirs(os.path.join(inputs, "nested"))
    synthetic_study(inputs)
    shutil.move(os.path.join(inputs, "qoi.gci.csv"), os.path.join(inputs, "nested", "qoi.gci.csv"))
    out_dir = os.path.join(work, "out")
    report = os.path.join(out_dir, "convergence.md")

    result = run("--input", inputs, "--output", report, "--commit", "abc123def",
                 "--build-type", "Release")
    assert result.returncode == 0, \
        f"exit code {result.returncode} without --strict: {result.stderr}"
    text = open(report).read() if os.path.exists(report) else ""
    for header in ("- commit: abc123def", "- date: ", "- machine: ", "- build type: Release"):
        assert header in text, f"header line '{header}' missing"
    assert "13 checks: 8 pass, 5 fail." in text, "summary count line missing or wrong"
    check_marks_follow_the_judge(inputs, text, "synthetic")

    check_order_rows(text)
    check_gci_and_bound_rows(text)
    check_units_in_tables(text)
    check_files_beside_the_report(inputs, out_dir, report, text)

    strict = run("--input", inputs, "--output", os.path.join(work, "strict", "c.md"), "--strict")
    assert strict.returncode == 1 and "Traceback" not in strict.stderr, \
        f"--strict with failures must exit 1, got {strict.returncode}: {strict.stderr}"


def check_order_rows(text):
    """The observed orders: rows in the band pass with their fitted order, and each row is
    marked as its pass column says, against the band both ways."""
    judged_in_band = [(field, norm) for field in ("n", "uz") for norm in ("L1", "L2", "Linf")
                      if (field, norm) != ("uz", "Linf")]
    for field, norm in judged_in_band:
        row = line_with(text, "| synthetic-1d-space | " + field + " | " + norm + " |")
        assert row.endswith("| PASS |"), f"{field} {norm} should pass: '{row}'"
        fitted = re.search(r"\| (\S+) ± ", row)
        assert fitted is not None and abs(float(fitted.group(1)) - 2.0) < 0.05, \
            f"{field} {norm} fitted order missing: '{row}'"
    t_l1 = line_with(text, "| synthetic-1d-space | T | L1 |")
    assert "**FAIL**" in t_l1 and re.search(r"\| 1(\.0+)? ± ", t_l1) is not None, \
        f"T L1 must fail showing its measured order 1: '{t_l1}'"
    # The judge's word against the band: shown as the pass column says, both ways.
    t_l2 = line_with(text, "| synthetic-1d-space | T | L2 |")
    assert t_l2.endswith("| PASS |") and re.search(r"\| 1(\.0+)? ± ", t_l2) is not None, \
        f"T L2 (order 1, pass column 1) must be shown as PASS with its order 1: '{t_l2}'"
    assert line_with(text, "- order synthetic-1d-space / T / L2") == "", \
        "T L2 is listed as failing although its pass column says 1"
    uz_linf = line_with(text, "| synthetic-1d-space | uz | Linf |")
    fitted = re.search(r"\| (\S+) ± ", uz_linf)
    assert (uz_linf.endswith("| **FAIL** |") and fitted is not None
            and abs(float(fitted.group(1)) - 2.0) < 0.05), \
        f"uz Linf (order 2, pass column 0) must be shown as failing: '{uz_linf}'"
    assert line_with(text, "- order synthetic-1d-space / uz / Linf: fitted 1.99") != "", \
        "uz Linf is missing from the failure list although its pass column says 0"
    assert line_with(text, "- order synthetic-1d-space / T / Linf: fitted 1") != "", \
        "failure list lacks the measured value of T Linf"


def check_gci_and_bound_rows(text):
    """GCI rows judged or shown as not checked (two grids, a time-step diagnostic); time-error
    bounds judged against the grid uncertainty."""
    shock = line_with(text, "| base-1d | shock_location |")
    assert "PASS" in shock and "FAIL" not in shock, f"GCI row should pass: '{shock}'"
    mach = line_with(text, "| base-1d | max_mach |")
    assert "**FAIL**" in mach and "oscillatory" in mach and "| 0.15 |" in mach, \
        f"GCI row should fail with its uncertainty 0.15: '{mach}'"
    assert line_with(text, "GCI base-1d / max_mach: observed order 1.5 (oscillatory) outside "
                     "the asymptotic range 2 ± 0.1") != "", \
        "GCI failure missing from the summary"

    two_grid = line_with(text, "| base-3d | shock_location |")
    assert "not checked (two grids" in two_grid and "FAIL" not in two_grid, \
        f"two-grid row must be shown but not checked: '{two_grid}'"

    diagnostic = line_with(text, "| real-time-x | max_mach | 1 | 3.1 |")
    assert "not checked (a diagnostic" in diagnostic and "FAIL" not in diagnostic, \
        f"a time-step study's GCI row must be shown but not checked: '{diagnostic}'"
    within = line_with(text, "| real-time-x | max_mach | 1 | 0.001 |")
    assert within.endswith("| 0.5 |  | PASS |"), f"bound 0.001 <= 0.002 must pass: '{within}'"
    above = line_with(text, "| real-time-x | shock_speed | sqrt(g sigma) | 0.005 |")
    assert above.endswith("| 2.5 |  | **FAIL** |"), f"bound 0.005 > 0.002 must fail: '{above}'"
    assert line_with(text, "- bound real-time-x / shock_speed: 0.005 (time error of the "
                     "production step (extrapolated)) above 0.002") != "", \
        "the failing bound is not listed with its measured value"
    no_bound = line_with(text, "| real-time-x | front_width_over_mfp_ft0.22 |")
    assert no_bound.endswith("| not checked |"), f"a row without a bound: '{no_bound}'"


def check_units_in_tables(text):
    """Units: a header that holds one quantity says them (the error table's pair orders, the
    orders table); a table of different quantities has a units column, filled from the one
    declaration per name (the error and GCI tables)."""
    errors_header = line_with(text, "| field | units | norm | h = 0.1 |")
    assert "p(0-1) [1]" in errors_header and "p(2-3) [1]" in errors_header, \
        f"error table lacks pair orders or their units: '{errors_header}'"
    n_row = line_with(text, "| n | 1/sigma^3 | L1 | 0.00505 |")
    assert n_row != "", "error table row of n L1 (with the units of n) missing"
    for field, units in (("uz", "sqrt(g sigma)"), ("T", "g sigma")):
        assert line_with(text, f"| {field} | {units} | L2 |") != "", \
            f"error table row of {field} lacks its units {units}"
    orders_header = line_with(text, "| study | field | norm | fitted p")
    assert ("fitted p (± s.e., points) [1]" in orders_header and "| design [1] |" in orders_header
            and "| band [1] |" in orders_header), f"orders header without units: '{orders_header}'"
    gci_header = line_with(text, "| study | quantity | units | phi1 (fine) |")
    assert "| p [1] |" in gci_header and "| GCI21 [%] |" in gci_header, \
        f"GCI header without its units column or units: '{gci_header}'"
    assert line_with(text, "| base-1d | shock_location | sigma | 2.0") != "", \
        "GCI row of shock_location lacks its units sigma"
    assert line_with(text, "| base-1d | max_mach | 1 | 3.1 |") != "", \
        "GCI row of max_mach lacks its units 1"


def check_files_beside_the_report(inputs, out_dir, report, text):
    """The plot linked, no temporary file left, the input tables copied flat and byte for
    byte; a second run replaces the tables and removes the plots of studies no longer in
    the input."""
    png = os.path.join(out_dir, "convergence-synthetic-1d-space.png")
    assert is_png(png), "PNG plot missing or not a PNG"
    assert "![synthetic-1d-space](convergence-synthetic-1d-space.png)" in text, "plot not linked"
    leftovers = [f for f in os.listdir(out_dir) if f.startswith((".partial", ".old"))]
    assert not leftovers, f"temporary files left: {leftovers}"
    # Every input table is kept beside the report, flat (the nested GCI table too), byte for
    # byte; a second run replaces the set rather than mixing old and new files.
    tables = os.path.join(out_dir, "convergence-tables")
    copied = sorted(os.listdir(tables)) if os.path.isdir(tables) else []
    expected = sorted(os.path.basename(p)
                      for p in glob.glob(os.path.join(inputs, "**", "*.csv"), recursive=True))
    assert copied == expected, f"tables copied {copied}, expected {expected}"
    assert (open(os.path.join(tables, "qoi.gci.csv")).read()
            == open(os.path.join(inputs, "nested", "qoi.gci.csv")).read()), "GCI table altered"
    open(os.path.join(tables, "stale.errors.csv"), "w").close()
    open(os.path.join(out_dir, "convergence-removed-study.png"), "w").close()
    assert run("--input", inputs, "--output", report).returncode == 0, "second report run failed"
    assert not os.path.exists(os.path.join(tables, "stale.errors.csv")), \
        "a stale table survived the second run"
    assert not os.path.exists(os.path.join(out_dir, "convergence-removed-study.png")), \
        "the plot of a study no longer in the input survived the second run"
    assert os.path.exists(png), "the second run removed a plot the report links"


def test_the_pass_column_not_the_band_decides_and_bad_input_is_refused(work_dir):
    work = work_dir
    # Numbers far outside the band, pass column 1: --strict has no failing check to exit on.
    lenient = os.path.join(work, "lenient")
    os.makedirs(lenient)
    write(os.path.join(lenient, "lenient.orders.csv"), ORDERS_HEADER,
          [("lenient", "T", "L2", 3, "1.0", "0.001", "1.0", "1.0", "2", "0.1", 1)])
    lenient_report = os.path.join(work, "lenient-out", "c.md")
    result = run("--input", lenient, "--output", lenient_report, "--strict")
    assert result.returncode == 0, (
        f"--strict when the judge passed every row must exit 0, "
        f"got {result.returncode}: {result.stderr}")
    text = open(lenient_report).read() if os.path.exists(lenient_report) else ""
    assert line_with(text, "| lenient | T | L2 |").endswith("| PASS |"), \
        "an out-of-band row with pass column 1 is not shown as PASS"
    check_marks_follow_the_judge(lenient, text, "lenient")

    # The writers put 1 or 0 in an order table's pass column; anything else is not a verdict.
    for cell in ("nan", "0.5"):
        not_a_verdict = os.path.join(work, f"pass-{cell}")
        os.makedirs(not_a_verdict)
        write(os.path.join(not_a_verdict, "x.orders.csv"), ORDERS_HEADER,
              [("x", "n", "L2", 3, "2", "0.001", "2", "2", "2", "0.1", cell)])
        out = os.path.join(work, f"pass-{cell}-out", "c.md")
        result = run("--input", not_a_verdict, "--output", out)
        assert result.returncode == 2 and f"pass = '{cell}' is not 1 or 0" in result.stderr, \
            f"pass {cell}: exit {result.returncode}, stderr '{result.stderr.strip()}'"
        assert not os.path.exists(out), f"a report was written from pass column {cell}"

    # A name without declared units is not shown with a blank: the input is refused.
    for kind, header, row, name in (
            ("errors", "study,field,norm,level,h,error", ("s", "pressure", "L1", 0, 1, 1),
             "pressure"),
            ("orders", ORDERS_HEADER, ("s", "rho", "L2", 3, 2, 0.001, 2, 2, 2, 0.1, 1), "rho"),
            ("bin-size", "study,quantity,phase,sigma_value,half_sigma_value,statistic,value,"
             "criterion,limit,pass", ("s", "T", 0.22, "nan", "nan", "median ratio", 1,
                                      "at_least", 0.9, 1), "median ratio")):
        unknown = os.path.join(work, f"unknown-{kind}")
        os.makedirs(unknown)
        write(os.path.join(unknown, f"x.{kind}.csv"), header, [row])
        out = os.path.join(work, f"unknown-{kind}-out", "c.md")
        result = run("--input", unknown, "--output", out)
        assert (result.returncode == 2 and f"'{name}'" in result.stderr
                and "units" in result.stderr), \
            f"{kind} naming {name}: exit {result.returncode}, stderr '{result.stderr.strip()}'"
        assert not os.path.exists(out), f"a report was written with {name} lacking units"

    bad = os.path.join(work, "bad")
    os.makedirs(bad)
    write(os.path.join(bad, "x.errors.csv"), "study,field,norm,h,error", [("s", "n", "L1", 1, 1)])
    bad_report = os.path.join(work, "bad-out", "convergence.md")
    result = run("--input", bad, "--output", bad_report)
    assert result.returncode == 2 and "first line must be" in result.stderr, \
        f"bad header: exit {result.returncode}, stderr '{result.stderr.strip()}'"
    assert not os.path.exists(bad_report), "a report was written from bad input"


def test_md_sampling_section(work_dir):
    """The MD sampling section, from its own input directory."""
    work = work_dir
    sampling_in = os.path.join(work, "sampling-input")
    os.makedirs(sampling_in)
    synthetic_sampling_study(sampling_in)
    sampling_report = os.path.join(work, "sampling-out", "convergence.md")
    result = run("--input", sampling_in, "--output", sampling_report, "--commit", "abc")
    assert result.returncode == 0, f"sampling report: exit {result.returncode}: {result.stderr}"
    text = open(sampling_report).read() if os.path.exists(sampling_report) else ""
    assert "## MD sampling convergence" in text, "MD sampling section missing"
    assert "6 checks: 4 pass, 2 fail." in text, "sampling summary count missing or wrong"
    check_marks_follow_the_judge(sampling_in, text, "synthetic sampling")
    row = line_with(text, "| synthetic-md-sampling | T_se_layer_rms | 0.22 |")
    assert row.endswith("| PASS |") and "-0.5 ± " in row and "-0.92–-0.08" in row, \
        f"T_se fit should pass with its band shown: '{row}'"
    row = line_with(text, "| synthetic-md-sampling | center_of_mass | 0.5 |")
    assert "**FAIL**" in row and "| 0.05 ± " in row, f"flat se must fail with slope 0.05: '{row}'"
    assert line_with(text, "- sampling synthetic-md-sampling / center_of_mass / f t 0.5: "
                     "slope 0.05") != "", "failing slope missing from the summary"
    row = line_with(text, "| synthetic-md-sampling | n_se_layer_rms | all |")
    assert row.endswith("| PASS |") and "| -0.95 ± " in row, \
        f"slope -0.95 with pass column 1 must be shown as PASS: '{row}'"
    assert line_with(text, "- sampling synthetic-md-sampling / n_se_layer_rms") == "", \
        "n_se_layer_rms is listed as failing although its pass column says 1"
    se_header = line_with(text, "| quantity | units | f t [1] | K = 2 | K = 4 | K = 8 | K = 16 |")
    assert se_header != "", "se table header (with its units column) missing"
    se_row = line_with(text, "| T_se_layer_rms | g sigma | 0.22 | 0.2121 |")
    assert se_row.endswith("| 0.075 |"), f"se table row wrong or without units: '{se_row}'"
    assert line_with(text, "| center_of_mass | sigma | 0.5 |") != "", \
        "se table row of center_of_mass lacks its units"
    fit_header = line_with(text, "| study | quantity | f t [1] | fitted slope")
    assert "[1] | expected [1] | band [1] |" in fit_header, \
        f"slope-fit header without units: '{fit_header}'"
    all_rows = [line for line in text.splitlines()
                if line.startswith("| n_se_layer_rms | 1/sigma^3 | all | ")]
    assert len(all_rows) == 1, f"the all-phases se row must appear once, found {len(all_rows)}"
    bins_t = line_with(text, "| synthetic-md-sampling | T | g sigma | 0.22 |")
    assert (bins_t.endswith("| PASS |") and ">= 0.9" in bins_t
            and "within 2 combined se | 1 | 0.96 |" in bins_t), \
        f"bin-size T should pass, a fraction in units 1: '{bins_t}'"
    bins_uz = line_with(text, "| synthetic-md-sampling | uz | sqrt(g sigma) | 0.22 |")
    assert "**FAIL**" in bins_uz and "| 0.8 |" in bins_uz, \
        f"bin-size uz should fail at 0.8: '{bins_uz}'"
    assert line_with(text, "- bin size synthetic-md-sampling / uz: fraction of layer bins "
                     "within 2 combined se = 0.8, required >= 0.9") != "", \
        "bin-size failure not summarised"
    shock = line_with(text, "| synthetic-md-sampling | shock_location | sigma | 0.22 | 17 | "
                      "17.5 | shift | sigma | 0.5 |")
    assert shock.endswith("| PASS |") and "<= 1.1" in shock, f"bin-size shock row wrong: '{shock}'"
    png = os.path.join(work, "sampling-out", "sampling-synthetic-md-sampling.png")
    assert is_png(png), "sampling PNG missing or not a PNG"
    assert "(sampling-synthetic-md-sampling.png)" in text, "sampling plot not linked"


def test_repository_tables(work_dir):
    """The repository's own tables: every mark of reports/convergence.md's input."""
    work = work_dir
    repository_tables = os.path.join(REPORTS, "convergence-tables")
    repository_report = os.path.join(work, "repository-out", "convergence.md")
    result = run("--input", repository_tables, "--output", repository_report, "--strict")
    text = open(repository_report).read() if os.path.exists(repository_report) else ""
    compared = check_marks_follow_the_judge(repository_tables, text, "repository")
    assert compared > 0, "no judged row of the repository's tables was compared"
    assert result.returncode == (1 if failure_list(text) else 0), \
        f"--strict exit {result.returncode} with {len(failure_list(text))} failing checks"
    print(f"{compared} rows of the repository's tables shown as their pass column says")


def test_term_shares_section(work_dir):
    """A *.term-shares.csv table: one row per term, a column per equation, blank where the term
    does not enter; a malformed share is refused."""
    inputs = os.path.join(work_dir, "shares-input")
    os.makedirs(inputs)
    header = "study,term,equation,rms,share"
    write(os.path.join(inputs, "mms-3d.term-shares.csv"), header,
          [("mms-3d", "advection", "mass", 0.35, 0.9675),
           ("mms-3d", "advection", "energy", 0.68, 0.1718),
           ("mms-3d", "conduction", "energy", 0.44, 0.1113)])
    report = os.path.join(work_dir, "shares-out", "convergence.md")
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr}"
    text = open(report).read()
    assert "### mms-3d: term shares" in text, "term-share table missing"
    assert line_with(text, "| term | mass | energy |") != "", "equation columns missing"
    assert line_with(text, "| advection | 0.968 | 0.172 |") != "", "advection row wrong"
    assert line_with(text, "| conduction |  | 0.111 |") != "", \
        "a term absent from an equation must leave its cell blank"
    write(os.path.join(inputs, "bad.term-shares.csv"), header,
          [("mms-3d", "gravity", "energy", 0.2, "lots")])
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 2 and "share = 'lots' is not a number" in result.stderr, \
        f"a malformed share must be refused with exit 2: {result.returncode} {result.stderr}"


def test_gci_plots(work_dir):
    """A figure per GCI study (three grids, or two), linked below the GCI table; the figure of
    a study no longer in the input goes with it."""
    inputs = os.path.join(work_dir, "gci-input")
    os.makedirs(inputs)
    three_grids = ("real-time-s2", "center_of_mass_ft0.25", 0.25, 0.5, 1, 17.682, 17.6827,
                   17.6834, 1.05, 17.6813, 4e-5, 4e-5, 5e-5, 1e-4, "monotonic", 2, 0.1, 2e-3, 1)
    stagnant = ("real-time-s2", "shock_width_ft0.22", 0.25, 0.5, 1, 3.6, 3.6, 3.6, "nan",
                "nan", 0, "nan", "nan", "nan", "stagnant", 2, 0.1, 0, 0)
    two_grids = ("real-3d", "max_mach", 0.5, 1.0, "nan", 11.17, 11.68, "nan", 2.0, 11.0, 0.046,
                 0.015, 0.06, "nan", "two-grids", 2, "nan", 0.67, "nan")
    table = os.path.join(inputs, "studies.gci.csv")
    write(table, GCI_HEADER, [three_grids, stagnant, two_grids])
    report = os.path.join(work_dir, "gci-out", "convergence.md")
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr}"
    text = open(report).read()
    gci_part = text.split("## Grid convergence index of the quantities of interest")[-1]
    for study in ("real-time-s2", "real-3d"):
        png = os.path.join(work_dir, "gci-out", f"convergence-{study}-gci.png")
        assert is_png(png), f"GCI figure of {study} missing or not a PNG"
        assert f"![{study}](convergence-{study}-gci.png)" in gci_part.split("\n## ")[0], \
            f"GCI figure of {study} not linked below the GCI table"

    write(table, GCI_HEADER, [three_grids, stagnant])
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 0, f"second run: exit {result.returncode}: {result.stderr}"
    assert not os.path.exists(os.path.join(work_dir, "gci-out", "convergence-real-3d-gci.png")), \
        "the GCI figure of a study no longer in the input survived"
    assert is_png(os.path.join(work_dir, "gci-out", "convergence-real-time-s2-gci.png")), \
        "the second run removed the GCI figure of a study still in the input"


def test_bounds_awaiting_a_rerun_are_shown_apart_and_not_counted(work_dir):
    """Bound tables of a former judge (subfolder awaiting-rerun/) appear in their own section
    with their former verdicts, count as no check, and are copied back into that subfolder
    so that the next report treats them alike; any other table there is refused."""
    inputs = os.path.join(work_dir, "input")
    waiting = os.path.join(inputs, "awaiting-rerun")
    os.makedirs(waiting)
    write(os.path.join(waiting, "old.bounds.csv"), BOUNDS_HEADER, [
        ("real-time-y", "shock_speed", 0.005, "time error (largest change)", 0.002,
         "grid uncertainty (finest of 0.4/0.2/0.1)", 0)])
    write(os.path.join(inputs, "new.bounds.csv"), BOUNDS_HEADER, [
        ("real-time-z", "max_mach", 0.001, "time error", 0.002, "grid uncertainty", 1)])
    report = os.path.join(work_dir, "out", "convergence.md")
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 0, result.stderr
    text = open(report).read()
    assert "1 checks: 1 pass, 0 fail." in text, "a former verdict was counted as a check"
    apart = text.split("## Bound checks awaiting a rerun")[-1].split("\n## ")[0]
    old = line_with(apart, "| real-time-y | shock_speed |")
    assert old.endswith("| 2.5 |  | former: fail |"), f"former verdict not shown: '{old}'"
    assert "real-time-y" not in text.split("## Bound checks awaiting a rerun")[0], \
        "a former verdict is shown among the judged checks"
    copied = os.path.join(work_dir, "out", "convergence-tables", "awaiting-rerun",
                          "old.bounds.csv")
    assert os.path.exists(copied), "the table awaiting a rerun was not copied into its folder"
    write(os.path.join(waiting, "old.gci.csv"), GCI_HEADER, [])
    refused = run("--input", inputs, "--output", report, "--commit", "abc")
    assert refused.returncode == 2 and "only bound checks can await a rerun" in refused.stderr, \
        f"a GCI table awaiting a rerun must be refused: {refused.returncode} {refused.stderr}"


def test_a_failing_time_bound_says_what_step_would_meet_it(work_dir):
    """A time-step study's failing bound gives the fraction of the production step at which
    the time error would equal the bound: (bound / value)^(1/p), p the observed order of the
    study's step triple where it converges monotonically below the formal order, the formal
    order otherwise, none where the changes grow; bounds of other studies get no such
    text."""
    inputs = os.path.join(work_dir, "input")
    os.makedirs(inputs)
    write(os.path.join(inputs, "t.bounds.csv"), BOUNDS_HEADER, [
        ("real-time-d1-x", "max_mach", 0.09, "time error", 0.01, "grid uncertainty", 0),
        ("real-time-d1-x", "shock_speed", 0.04, "time error", 0.01, "grid uncertainty", 0),
        ("real-time-d1-x", "shock_width_ft0.22", 0.04, "time error", 0.01, "grid uncertainty", 0),
        ("real-1d-integrator-x", "max_mach", 0.09, "difference", 0.01, "grid uncertainty", 0)])
    steps = (0.25, 0.5, 1.0)
    write(os.path.join(inputs, "t.gci.csv"), GCI_HEADER, [
        ("real-time-d1-x", "max_mach", *steps, 3.0, 3.01, 3.03, 1.0, 2.99, 0.003, 0.003, 0.01,
         0.02, "monotonic", 2, 0.1, 0.03, float("nan")),
        ("real-time-d1-x", "shock_speed", *steps, 4.0, 4.1, 4.0, 1.0, 4.1, 0.02, 0.02, 0.05,
         0.05, "oscillatory", 2, 0.1, 0.05, float("nan")),
        ("real-time-d1-x", "shock_width_ft0.22", *steps, 3.0, 3.1, 3.11, -3.0, 3.1, 0.02, 0.02,
         0.05, 0.05, "monotonic", 2, 0.1, 0.05, float("nan"))])
    report = os.path.join(work_dir, "out", "convergence.md")
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 0, result.stderr
    failures = failure_list(open(report).read())
    observed = next(f for f in failures if "real-time-d1-x / max_mach" in f)
    assert "a step of 0.11 of the production step" in observed and "observed temporal order 1" \
        in observed, f"order-1 step not given: '{observed}'"  # (0.01 / 0.09)^1
    formal = next(f for f in failures if "real-time-d1-x / shock_speed" in f)
    assert "a step of 0.5 of the production step" in formal and "formal temporal order 2" \
        in formal, f"formal-order step not given: '{formal}'"  # (0.01 / 0.04)^(1/2)
    growing = next(f for f in failures if "real-time-d1-x / shock_width_ft0.22:" in f)
    assert "no step is estimated: its changes grow" in growing and "a step of" not in growing, \
        f"a step estimated for a triple whose changes grow: '{growing}'"
    other = next(f for f in failures if "real-1d-integrator-x" in f)
    assert "production step" not in other, f"a step given for another study: '{other}'"


def test_known_failures_are_listed_with_their_reasons(work_dir):
    """The report gives, beside the failing checks, every known-failure line of the
    repository's status files: its test pattern and its reason, one table row each."""
    known = [(pattern, reason) for _, _, pattern, labels, reason
             in report_common.status_lines(REPOSITORY) if labels and "known-failure" in labels]
    assert known, "the repository declares no known failure: nothing to test"
    inputs = os.path.join(work_dir, "input")
    os.makedirs(inputs)
    synthetic_study(inputs)
    report = os.path.join(work_dir, "out", "convergence.md")
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 0, result.stderr
    section = open(report).read().split("## Known failures and why")[-1].split("\n## ")[0]
    rows = [line for line in section.splitlines() if line.startswith("| `")]
    assert len(rows) == len(known), f"{len(rows)} rows for {len(known)} known failures"
    for (pattern, reason), row in zip(known, rows):
        cells = table_cells(row)
        assert cells[1] == f"`{pattern}`" and cells[2] == reason, \
            f"row '{row}' is not the status line {pattern}: {reason}"


def theoretical_orders_file(directory, declared):
    path = os.path.join(directory, "orders.csv")
    with open(path, "w") as f:
        f.write("# synthetic\nquantity,order,reason\n")
        f.writelines(f"{q},{p},{why}\n" for q, p, why in declared)
    return path


def first_order_rows(study, judged):
    """A triple of phi = 3 + h per (quantity, design order, pass) as the C++ judge writes it:
    observed order exactly 1."""
    rows = []
    for quantity, design, verdict in judged:
        h, phi = (0.1, 0.2, 0.4), (3.1, 3.2, 3.4)
        uncertainty = (1.25 if verdict else 3.0) * 0.1
        rows.append((study, quantity, *h, *phi, 1.0, 3.0, 0.1 / 3.1, 0.1, 0.04, 0.08,
                     "monotonic", design, 0.1, uncertainty, verdict))
    return rows


def test_each_real_problem_row_is_judged_at_its_theoretical_order(work_dir):
    """A real-problem grid triple is judged against its quantity's theoretical order, declared
    once with its reason: the report shows both, and a first-order triple passes where the
    order is 1 and fails where it is 2 (the judge: support.GciRows.EachQuantityIsJudgedAt
    ItsTheoreticalOrder). A table judged at another order than the declared one is refused,
    so that no stale verdict is shown."""
    orders = theoretical_orders_file(work_dir, [("width_over_mfp_ft0.25", 1, "whole-cells"),
                                                ("max_mach", 2, "sampled-maximum")])
    inputs = os.path.join(work_dir, "input")
    os.makedirs(inputs)
    write(os.path.join(inputs, "r.gci.csv"), GCI_HEADER, first_order_rows(
        "real-1d-base-finest", [("width_over_mfp_ft0.25", 1, 1), ("max_mach", 2, 0)]))
    report = os.path.join(work_dir, "out", "convergence.md")
    result = run("--input", inputs, "--output", report, "--commit", "abc",
                 "--theoretical-orders", orders)
    assert result.returncode == 0, result.stderr
    text = open(report).read()
    rows = markdown_tables(text)["## Grid convergence index of the quantities of interest"]
    shown = {r["quantity"]: r for r in rows}
    first = shown["width_over_mfp_ft0.25"]
    assert (first["theoretical p [1]"], first["reason"]) == ("1", "whole-cells"), first
    assert first["result"].startswith("PASS"), f"order 1 against 1 not passed: {first}"
    second = shown["max_mach"]
    assert (second["theoretical p [1]"], second["reason"]) == ("2", "sampled-maximum"), second
    assert second["result"].startswith("**FAIL**"), f"order 1 against 2 passed: {second}"
    failure = next(f for f in failure_list(text) if "max_mach" in f)
    assert "outside the asymptotic range 2 ± 0.1 (theory: sampled-maximum)" in failure, failure
    assert "verification/README.md" in text.split("## Grid convergence index")[1], \
        "the GCI section does not cite the theory"

    stale = os.path.join(work_dir, "stale")
    os.makedirs(stale)
    write(os.path.join(stale, "r.gci.csv"), GCI_HEADER, first_order_rows(
        "real-1d-base-finest", [("width_over_mfp_ft0.25", 2, 0)]))
    out = os.path.join(work_dir, "stale-out", "convergence.md")
    result = run("--input", stale, "--output", out, "--theoretical-orders", orders)
    assert result.returncode == 2 and "judged at order 2, its theoretical order is 1" in \
        result.stderr, f"exit {result.returncode}: {result.stderr.strip()}"
    assert not os.path.exists(out), "a report was written from a table judged at another order"


def test_a_real_problem_quantity_without_a_theoretical_order_is_refused(work_dir):
    """A grid triple of the real problem whose quantity has no declared order has nothing to
    be judged against: unreadable input, no report. A time-step study's own triple is judged
    at its integrator's temporal order and needs none."""
    orders = theoretical_orders_file(work_dir, [("max_mach", 2, "sampled-maximum")])
    studies = (("real-1d-base-fine", True), ("real-time-d1-paper-implicit-s2-grid", True),
               ("real-time-d1-paper-implicit-s2", False))
    for study, refused in studies:
        inputs = os.path.join(work_dir, study)
        os.makedirs(inputs)
        write(os.path.join(inputs, "r.gci.csv"), GCI_HEADER,
              first_order_rows(study, [("shock_speed", 1, float("nan"))]))
        out = os.path.join(work_dir, study + "-out", "convergence.md")
        result = run("--input", inputs, "--output", out, "--theoretical-orders", orders)
        if refused:
            assert result.returncode == 2 and "'shock_speed'" not in result.stderr and \
                "shock_speed: no theoretical order declared" in result.stderr, \
                f"{study}: exit {result.returncode}: {result.stderr.strip()}"
            assert not os.path.exists(out), f"{study}: a report was written"
        else:
            assert result.returncode == 0, f"{study}: {result.stderr}"


def test_the_theoretical_orders_cover_every_quantity_of_the_grid_studies():
    """The repository's table declares an order for every quantity the real problem's grid
    studies write: those of the stored tables and those test_real_problem.cpp names."""
    orders = make_convergence_report.read_theoretical_orders(
        os.path.join(REPOSITORY, make_convergence_report.THEORETICAL_ORDERS))
    tables = os.path.join(REPORTS, "convergence-tables")
    written = {row["quantity"] for kind in ("gci", "bounds")
               for path in glob.glob(os.path.join(tables, "**", f"real-*.{kind}.csv"),
                                     recursive=True)
               for row in csv_rows(path)}
    source = os.path.join(REPOSITORY, "verification", "grid-studies",
                          "test_real_problem.cpp")
    named = set(re.findall(r'q\["([^"]+)"\]', open(source).read()))
    assert len(named) >= 7 and len(written) >= 11, (named, written)
    undeclared = sorted((written | named) - set(orders))
    assert not undeclared, f"no theoretical order declared for {undeclared}"
    assert {p for p, _ in orders.values()} <= {1.0, 2.0}, orders


def test_an_integrator_difference_is_set_against_its_own_time_error(work_dir):
    """A fast integrator's failing difference from the reference is explained where the
    time-step study of the same setting measures a time error at its step that covers it, and
    said to be unexplained where it does not, or where no such study exists."""
    inputs = os.path.join(work_dir, "input")
    os.makedirs(inputs)
    write(os.path.join(inputs, "b.bounds.csv"), BOUNDS_HEADER, [
        ("real-1d-integrator-paper-implicit-s2", "max_mach", 0.02, "difference", 0.01,
         "grid uncertainty", 0),
        ("real-1d-integrator-paper-implicit-s2", "shock_speed", 0.02, "difference", 0.01,
         "grid uncertainty", 0),
        ("real-1d-integrator-paper-implicit-s4", "max_mach", 0.02, "difference", 0.01,
         "grid uncertainty", 0),
        ("real-time-d1-paper-implicit-s2", "max_mach", 0.03, "time error", 0.01,
         "grid uncertainty", 0),
        ("real-time-d1-paper-implicit-s2", "shock_speed", 0.015, "time error", 0.01,
         "grid uncertainty", 0)])
    report = os.path.join(work_dir, "out", "convergence.md")
    result = run("--input", inputs, "--output", report, "--commit", "abc")
    assert result.returncode == 0, result.stderr
    text = open(report).read()
    rows = markdown_tables(text)["## Errors within their uncertainty"]
    column = "time error of this integrator at its step"
    cells = {(r["study"], r["quantity"]): r[column] for r in rows}
    assert cells[("real-1d-integrator-paper-implicit-s2", "max_mach")] == "0.03", cells
    assert cells[("real-1d-integrator-paper-implicit-s4", "max_mach")] == "no time-step study"
    assert cells[("real-time-d1-paper-implicit-s2", "max_mach")] == "", cells
    failures = failure_list(text)

    def failure(study, quantity):
        return next(f for f in failures if f"{study} / {quantity}:" in f)
    assert "explained: this setting's own time error at its step, 0.03" in \
        failure("real-1d-integrator-paper-implicit-s2", "max_mach")
    assert "not explained by its time error at its step, 0.015" in \
        failure("real-1d-integrator-paper-implicit-s2", "shock_speed")
    assert "unexplained by measurement: no time-step study" in \
        failure("real-1d-integrator-paper-implicit-s4", "max_mach")
