"""Writes reports/convergence.md (+ PNG plots beside it) from CSV error tables and summaries.

Usage:
    shaker-convergence-report --input DIR [--output reports/convergence.md] [--repository DIR]
                              [--build-dir BUILD] [--build-type TYPE] [--commit SHA] [--strict]

(or `python3 -m granular_shaker.reports.make_convergence_report ...`).

Every file under DIR (searched recursively) whose name ends in one of the suffixes below is
read; verification/support/error_table.hpp and verification/sampling/md_sampling.cpp write
exactly these files. The first line of each is the header shown; numbers are decimal (nan
allowed); names contain no commas.

  *.errors.csv   study,field,norm,level,h,error
      One discrete error norm of one field on one level of one study. `h` is the grid spacing
      (spatial studies) or time step (temporal studies); `level` 0 is the coarsest. `norm` is
      L1, L2 or Linf.
  *.orders.csv   study,field,norm,fit_points,fitted_order,order_std_error,pair_order_finest,
                 pair_order_next,design_order,tolerance,pass
      The acceptance check of one error series: the least-squares order over the `fit_points`
      finest levels, the two-level orders of the finest and next pair, the design order and
      the band half-width. The judge (OrderCheck::pass) passes it when the fitted and both
      pair orders lie within `tolerance` of `design_order` (the next pair may be missing, nan,
      only when fit_points < 3).
  *.gci.csv      study,quantity,h1,h2,h3,phi1,phi2,phi3,order,phi_extrapolated,
                 relative_difference21,extrapolated_error21,gci21,gci32,convergence,
                 design_order,order_tolerance,uncertainty1,pass
      A quantity of interest on three grids (1 finest) with Roache's GCI (Fs = 1.25, relative
      quantities as fractions), the observed order (negative where the changes grow under
      refinement) and the uncertainty of phi1 in phi's units (GciRow: Fs 1.25 in the
      asymptotic range, Fs 3 outside it, at least half the range where the triple does not
      converge monotonically). The judge (GciRow::pass) places the triple in the asymptotic
      range when it converges monotonically at an order within order_tolerance of
      design_order. For the real problem's grid studies (study real-*, but for a time-step
      study's own rows, real-time-* without -grid, judged at their integrator's temporal order)
      design_order is the quantity's theoretical order, declared once with its reason in
      THEORETICAL_ORDERS (verification/grid-studies/theoretical_orders.csv, explained in
      verification/README.md): a quantity it does not declare, or a row judged at another
      order (rejudge the table: rejudge_gci --orders), is unreadable input. The report shows
      each row's theoretical order and the short name of its reason. A two-grid row
      (convergence "two-grids"; h3, phi3, gci32 and pass nan;
      assumed order, Fs = 3) is shown as "not checked" and is not counted as a check. Each
      study gets a figure below the table: phi against h per quantity, with phi_extrapolated
      and the band phi1 ± uncertainty1.
  *.bounds.csv   study,quantity,value,value_basis,bound,bound_basis,pass
      A study's claim that an error lies within an uncertainty (BoundCheck): the time error of
      the production step within the grid error (time-step studies), |3D - 1D| within the
      combined grid uncertainty, a fast integrator's difference from the reference within the
      reference's grid uncertainty. The judge passes it when value <= bound; a row without a
      bound (nan) is "not checked". A time-step study's GCI rows are diagnostics there (their
      order sets the safety factor of the time error), shown as "not checked". Bound tables
      in the subfolder awaiting-rerun/ were computed by a former rule or protocol: they are
      shown apart, with their former verdicts, and are not checks of the report.
  *.sampling.csv      study,quantity,phase,K,blocks,degrees_of_freedom,effective_K,missing,
                      standard_error
      MD sampling convergence (verification/sampling/md_sampling.hpp): the standard error
      of one quantity (phase = f t, nan for all phases) from blocks of K sampled cycles;
      cycles without a value (missing) make the effective number of cycles effective_K < K.
  *.sampling-fit.csv  study,quantity,phase,fit_points,fitted_slope,slope_std_error,
                      expected_slope,band,pass
      The least-squares slope of ln se against ln K; the judge (SamplingFit::pass) passes it
      when |slope - expected_slope| <= band (the band follows from the degrees of freedom of
      each standard error).
  *.term-shares.csv   study,term,equation,rms,share
      A manufactured solution's source split by term (verification/mms/mms_run.hpp,
      term_shares): the root mean square of one term's part in one equation, and its share of
      the sum over the terms there. Shown as a table; the check (MmsTermShares3D) is ctest's.
  *.bin-size.csv      study,quantity,phase,sigma_value,half_sigma_value,statistic,value,
                      criterion,limit,pass
      Bin size sigma against sigma/2: `statistic` names `value`; the judge
      (BinSizeCheck::pass) passes criterion at_least when value >= limit, at_most when
      value <= limit.

The CSV files carry no units: QUANTITY_UNITS below declares those of every field and
quantity name they use (docs/units.md), and a name without units is unreadable input (exit 2).
The report gives them in each table: in the header of a column that holds one quantity, in a
`units` column where the rows hold different quantities.

One judge decides pass or fail: the C++ side that writes the `pass` column (error_table.cpp,
md_sampling.cpp), which the ctest tests assert with. This report shows that column as the
verdict of each row (1 PASS, 0 **FAIL**, nan "not checked") and never re-decides it from the
numbers; the band rules above are the judge's, quoted for the reader. A `pass` cell other than
1 or 0 (or nan in a GCI table) is unreadable input. A failing check is listed with its measured
value, never dropped. The exit code is 0 unless --strict is given and a check fails (then 1);
2 for unreadable input.
"""
import argparse
import csv
import glob
import math
import os
import re
import shutil
import sys
import tempfile
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.ticker  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from granular_shaker.repository import add_repository_option, repository_argument  # noqa: E402
from granular_shaker.reports import report_common as rc  # noqa: E402

ERRORS_HEADER = ["study", "field", "norm", "level", "h", "error"]
ORDERS_HEADER = ["study", "field", "norm", "fit_points", "fitted_order", "order_std_error",
                 "pair_order_finest", "pair_order_next", "design_order", "tolerance", "pass"]
GCI_HEADER = ["study", "quantity", "h1", "h2", "h3", "phi1", "phi2", "phi3", "order",
              "phi_extrapolated", "relative_difference21", "extrapolated_error21", "gci21",
              "gci32", "convergence", "design_order", "order_tolerance", "uncertainty1", "pass"]
SAMPLING_HEADER = ["study", "quantity", "phase", "K", "blocks", "degrees_of_freedom",
                   "effective_K", "missing", "standard_error"]
SAMPLING_FIT_HEADER = ["study", "quantity", "phase", "fit_points", "fitted_slope",
                       "slope_std_error", "expected_slope", "band", "pass"]
BIN_SIZE_HEADER = ["study", "quantity", "phase", "sigma_value", "half_sigma_value", "statistic",
                   "value", "criterion", "limit", "pass"]
TERM_SHARES_HEADER = ["study", "term", "equation", "rms", "share"]
BOUNDS_HEADER = ["study", "quantity", "value", "value_basis", "bound", "bound_basis", "pass"]
# A subfolder of the input whose bound checks a former judge computed (awaiting_section).
AWAITING_RERUN = "awaiting-rerun"
TEXT_COLUMNS = {"study", "field", "norm", "quantity", "convergence", "statistic", "criterion",
                "term", "equation", "value_basis", "bound_basis"}
# The tables whose judge leaves some rows unchecked (pass nan).
MAY_BE_UNCHECKED = (GCI_HEADER, BOUNDS_HEADER)
NORM_ORDER = {"L1": 0, "L2": 1, "Linf": 2}

# The units of every field and quantity the C++ writers name (docs/units.md): the fields of the
# manufactured-solution and real-problem error tables (verification/mms/mms_run.hpp,
# field_names) and of the bin-size checks; the quantities of interest of the real-problem GCI
# tables (verification/mms/test_real_problem.cpp, defined in docs/analysis.md); and the MD
# sampling quantities (verification/sampling/test_md_sampling.cpp, md_sampling.cpp). An
# error norm (mean |d|, sqrt(mean d^2), max |d|) and a standard error have the units of their
# quantity.
QUANTITY_UNITS = {
    "n": "1/sigma^3",
    "nu": rc.DIMENSIONLESS,
    "ux": "sqrt(g sigma)",
    "uy": "sqrt(g sigma)",
    "uz": "sqrt(g sigma)",
    "T": "g sigma",
    "center_of_mass": "sigma",
    "shock_location": "sigma",
    "shock_width": "sigma",
    "shock_speed": "sqrt(g sigma)",  # plate frame
    "max_mach": rc.DIMENSIONLESS,
    "width_over_mfp": rc.DIMENSIONLESS,  # d/xi
    "front_width_over_mfp": rc.DIMENSIONLESS,
    # The RMS over the layer's bins of the standard error of n and of T.
    "n_se_layer_rms": "1/sigma^3",
    "T_se_layer_rms": "g sigma",
}
# A quantity taken at a phase or over a window of phases carries it in its name
# (center_of_mass_ft0.25, max_mach_ft0.08-0.13); its units are those of the quantity.
PHASE_SUFFIX = re.compile(r"_ft[0-9.]+(-[0-9.]+)?$")


class InputProblem(Exception):
    pass


# The order of grid convergence each real-problem quantity can reach, with its reason: one
# table of the repository, read here and by verification/grid-studies/test_real_problem.cpp
# and rejudge_gci.
THEORETICAL_ORDERS = os.path.join("verification", "grid-studies", "theoretical_orders.csv")
THEORY_SECTION = "verification/README.md, \"What order the real problem's quantities can reach\""


def read_theoretical_orders(path):
    """{quantity: (order, reason)} of a `quantity,order,reason` table ('#' comment lines)."""
    try:
        with open(path, newline="") as f:
            lines = [line for line in f if line.strip() and not line.startswith("#")]
    except OSError as error:
        raise InputProblem(f"theoretical orders: {error}") from None
    rows = list(csv.reader(lines))
    if not rows or rows[0] != ["quantity", "order", "reason"]:
        raise InputProblem(f"{path}: first line must be 'quantity,order,reason'")
    orders = {}
    for row in rows[1:]:
        try:
            quantity, order, reason = row
            order = float(order)
        except ValueError:
            raise InputProblem(f"{path}: '{','.join(row)}' is not quantity,order,reason") from None
        if quantity in orders or not reason or not 0.5 <= order <= 10:
            raise InputProblem(f"{path}: '{','.join(row)}': a quantity once, an order in "
                               "[0.5, 10] and a reason")
        orders[quantity] = (order, reason)
    return orders


def is_time_step_triple(study):
    """A time-step study's own rows (refining the step, not the grid): judged at the
    integrator's temporal order, not at a quantity's spatial one."""
    return study.startswith("real-time-") and not study.endswith("-grid")


def theory_of(row, orders):
    """(order, reason) a GCI row is judged against; InputProblem where a real-problem spatial
    row's quantity has no declared order or the table judged it at another."""
    if is_time_step_triple(row["study"]):
        return row["design_order"], "integrator's temporal order"
    if not row["study"].startswith("real-"):
        return row["design_order"], "design order"
    if row["quantity"] not in orders:
        raise InputProblem(f"GCI {row['study']} / {row['quantity']}: no theoretical order "
                           f"declared in {THEORETICAL_ORDERS}")
    order, reason = orders[row["quantity"]]
    if row["design_order"] != order:
        raise InputProblem(f"GCI {row['study']} / {row['quantity']}: judged at order "
                           f"{rc.fmt(row['design_order'])}, its theoretical order is "
                           f"{rc.fmt(order)} ({reason}): judge the table anew "
                           "(rejudge_gci --orders)")
    return order, reason


def units_of(name):
    """The units of a field or quantity named in the tables; InputProblem if it has none."""
    try:
        return rc.units_of(QUANTITY_UNITS, PHASE_SUFFIX.sub("", name))
    except rc.UnknownUnits as unknown:
        raise InputProblem(f"{unknown}: declare them in QUANTITY_UNITS of "
                           "granular_shaker/reports/make_convergence_report.py") from None


def bin_size_value_units(row):
    """The units of a bin-size check's value and limit: a fraction of bins is a number, a
    difference or shift of the quantity has the quantity's units (the statistics of
    verification/sampling/test_md_sampling.cpp)."""
    statistic = row["statistic"]
    if statistic.startswith("fraction"):
        return rc.DIMENSIONLESS
    if statistic.startswith(("max abs difference", "shift")):
        return units_of(row["quantity"])
    raise InputProblem(f"bin-size check of {row['quantity']}: no units known for the statistic "
                       f"'{statistic}'")


def read_csv(path, header):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or rows[0] != header:
        raise InputProblem(f"{path}: first line must be '{','.join(header)}'")
    records = []
    for number, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise InputProblem(f"{path}:{number}: expected {len(header)} columns, found {len(row)}")
        record = {}
        for key, cell in zip(header, row):
            if key in TEXT_COLUMNS:
                record[key] = cell
            else:
                try:
                    record[key] = float(cell)
                except ValueError:
                    raise InputProblem(f"{path}:{number}: {key} = '{cell}' is not a number")
        if "pass" in record and not is_judge_verdict(record["pass"], header):
            allowed = "1, 0 or nan" if header in MAY_BE_UNCHECKED else "1 or 0"
            cell = row[header.index("pass")]
            raise InputProblem(f"{path}:{number}: pass = '{cell}' is not {allowed}")
        records.append(record)
    return records


def is_judge_verdict(cell, header):
    # The C++ writers put 1 or 0 in every pass column but two: a GCI row they do not check (two
    # grids, or a ratio the study reads as a diagnostic) and a bound that has no estimate carry
    # nan. Anything else is not a verdict to show.
    return cell in (0.0, 1.0) or (math.isnan(cell) and header in MAY_BE_UNCHECKED)


TABLES_DIRECTORY = "convergence-tables"


def copied_name(name):
    """The input file's name in the copied tables: flat, but for the tables awaiting a rerun,
    which stay in their folder so that the next report reads them as such again."""
    if is_awaiting_rerun(name):
        return os.path.join(AWAITING_RERUN, os.path.basename(name))
    return os.path.basename(name)


def is_awaiting_rerun(relative_path):
    return relative_path.split(os.sep)[0] == AWAITING_RERUN


def copy_tables(input_dir, files, tables):
    """Replaces `tables` by a copy of the input CSV files (copied_name), filled aside and
    renamed into place, so a reader never sees a half-copied set."""
    parent = os.path.dirname(tables)
    os.makedirs(parent, exist_ok=True)  # no plot has made it when the input has no error table
    staging = tempfile.mkdtemp(dir=parent, prefix=".partial-tables-")
    try:
        for name in files:
            target = os.path.join(staging, copied_name(name))
            os.makedirs(os.path.dirname(target), exist_ok=True)
            shutil.copyfile(os.path.join(input_dir, name), target)
        old = None
        if os.path.exists(tables):
            old = tempfile.mkdtemp(dir=parent, prefix=".old-tables-")
            os.replace(tables, os.path.join(old, "tables"))
        os.replace(staging, tables)
        if old:
            shutil.rmtree(old)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


def remove_stale_plots(out_dir, report_text):
    """Deletes the plots this generator made for studies that are no longer in its input
    (a renamed or removed test), so the directory holds only what the report links."""
    for path in glob.glob(os.path.join(out_dir, "convergence-*.png")) + \
            glob.glob(os.path.join(out_dir, "sampling-*.png")):
        if f"({os.path.basename(path)})" not in report_text:
            os.unlink(path)


def read_inputs(directory):
    found = {"errors": [], "orders": [], "gci": [], "bounds": [], "sampling": [],
             "sampling-fit": [], "bin-size": [], "term-shares": [], "awaiting-bounds": []}
    files = []
    for kind, header in (("errors", ERRORS_HEADER), ("orders", ORDERS_HEADER), ("gci", GCI_HEADER),
                         ("bounds", BOUNDS_HEADER), ("sampling", SAMPLING_HEADER),
                         ("sampling-fit", SAMPLING_FIT_HEADER), ("bin-size", BIN_SIZE_HEADER),
                         ("term-shares", TERM_SHARES_HEADER)):
        for path in sorted(glob.glob(os.path.join(directory, "**", f"*.{kind}.csv"),
                                     recursive=True)):
            records = read_csv(path, header)
            for record in records:  # every name must have units before anything is written
                if kind == "term-shares":
                    continue  # shares are fractions of a sum; rms is per-equation source
                try:
                    units_of(record.get("field", record.get("quantity")))
                    if kind == "bin-size":
                        bin_size_value_units(record)
                except InputProblem as problem:
                    raise InputProblem(f"{path}: {problem}") from None
            relative = os.path.relpath(path, directory)
            awaiting = is_awaiting_rerun(relative)
            if awaiting and kind != "bounds":
                raise InputProblem(f"{path}: only bound checks can await a rerun")
            found["awaiting-bounds" if awaiting else kind].extend(records)
            files.append(relative)
    return found, files


PASSED, FAILED, NOT_CHECKED = "PASS", "**FAIL**", "not checked"


def judged_mark(pass_cell):
    """The mark of one table row: its `pass` column as the C++ judge wrote it. The report shows
    that verdict and never re-decides it from the numbers (one judge: error_table.cpp and
    md_sampling.cpp, which the ctest tests assert with)."""
    if math.isnan(pass_cell):
        return NOT_CHECKED
    return PASSED if pass_cell == 1 else FAILED


def judged_table(header, rows, render_row, describe_failure, failures, none_found):
    """A markdown table of rows carrying a `pass` column, then a blank line; one row saying
    `none_found` stands for none. Appends the measured values of each failing row to
    `failures`. Returns (lines, checks): rows the judge did not check are not checks."""
    columns = header.count("|") - 1
    lines, checks = [header, "|---" * columns + "|"], 0
    for row in rows:
        mark = judged_mark(row["pass"])
        lines.append(render_row(row, mark))
        checks += mark != NOT_CHECKED
        if mark == FAILED:
            failures.append(describe_failure(row))
    if not rows:
        lines.append(f"| ({none_found}) |" + " |" * (columns - 1))
    return lines + [""], checks


def series_of(errors):
    series = {}
    for row in errors:
        series.setdefault(row["study"], {}).setdefault((row["field"], row["norm"]), []).append(row)
    for study in series.values():
        for key in study:
            study[key].sort(key=lambda r: -r["h"])  # coarse to fine
    return series


def pair_orders(rows):
    out = []
    for coarse, fine in zip(rows, rows[1:]):
        if coarse["error"] > 0 and fine["error"] > 0 and coarse["h"] > fine["h"]:
            out.append(math.log(coarse["error"] / fine["error"])
                       / math.log(coarse["h"] / fine["h"]))
        else:
            out.append(float("nan"))
    return out


def safe_name(study):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", study)


def step_axis(study):
    """The x axis of a study's plots: what its h is, with units. A temporal manufactured-solution
    study refines the time step, a real-problem time-step study scales the production step."""
    if "MmsTime" in study:
        return rc.with_units("time step dt", "sqrt(sigma/g)")
    if is_time_step_triple(study):
        return rc.with_units("time-step scale", rc.DIMENSIONLESS)
    return rc.with_units("cell size h", "sigma")


ERROR_PANEL_COLUMNS = 4


def panel_grid(fig, panels, width=3.6, height=3.1):
    """`panels` axes in `fig`, at most ERROR_PANEL_COLUMNS to a line, the figure sized to
    them; the spare ones hidden."""
    columns = min(ERROR_PANEL_COLUMNS, panels)
    lines = -(-panels // columns)
    fig.set_size_inches(width * columns, height * lines + 0.6)
    axes = fig.subplots(lines, columns, squeeze=False)
    for ax in axes.flat[panels:]:
        ax.set_visible(False)
    return axes.flat[:panels]


def suptitle(fig, text):
    """A figure title wrapped to the figure's width."""
    fig.suptitle(textwrap.fill(text, int(11 * fig.get_figwidth())), fontsize=10)


def figure_errors(study, series, design_orders):
    """One panel per quantity (its units on the error axis), its norms (and the phases at
    which it is taken) against h, with the design order's slopes."""
    quantities = {}
    for (field, norm), rows in sorted(series.items()):
        quantities.setdefault(PHASE_SUFFIX.sub("", field), []).append((field, norm, rows))
    fig = plt.figure()
    axes = panel_grid(fig, len(quantities))
    for ax, (quantity, members) in zip(axes, quantities.items()):
        finest = []
        for field, norm, rows in sorted(members, key=lambda m: (m[0], NORM_ORDER.get(m[1], 9))):
            h = np.array([r["h"] for r in rows])
            e = np.array([r["error"] for r in rows])
            keep = (h > 0) & (e > 0)
            if not keep.any():
                continue
            label = norm if field == quantity else f"f t {field[len(quantity) + 3:]}, {norm}"
            ax.loglog(h[keep], e[keep], "o-", ms=4, label=label)
            finest.append((h[keep].min(), e[keep][np.argmin(h[keep])], h[keep].max()))
        hs = np.array([min(f[0] for f in finest), max(f[2] for f in finest)]) if finest \
            else np.zeros(2)
        for p in sorted(design_orders) if hs[1] > hs[0] else []:
            anchor = float(np.exp(np.mean([np.log(f[1]) for f in finest])))
            ax.loglog(hs, anchor * (hs / hs[0]) ** p, "k--", lw=1, label=f"slope {p:g}")
        if not finest:
            ax.text(0.5, 0.5, "zero on every level", transform=ax.transAxes, ha="center")
            ax.set_xticks([])
            ax.set_yticks([])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(quantity, fontsize=9)
        ax.set_xlabel(step_axis(study), fontsize=8)
        ax.set_ylabel(rc.with_units("error", units_of(quantity)), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", alpha=0.3)
        if finest:
            ax.legend(fontsize=6)
    suptitle(fig, f"{study}: error norms against the {step_axis(study)}")
    fig.tight_layout()
    return fig


def label_log_ticks(ax, values):
    """Ticks a log x axis at exactly `values`, without minor-tick labels."""
    ticks = sorted(set(values))
    ax.set_xticks(ticks)
    ax.set_xticklabels([f"{v:g}" for v in ticks])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def gci_order_text(r):
    assumed = " (assumed)" if r["convergence"] == "two-grids" else ""
    return f"p = {rc.fmt(r['order'], 3)}{assumed}"


def gci_panel(ax, r, h_label):
    """One GCI row: phi on its grids against h, phi_extrapolated and phi1 ± uncertainty1."""
    grids = [(r[f"h{i}"], r[f"phi{i}"]) for i in (1, 2, 3)
             if math.isfinite(r[f"h{i}"]) and math.isfinite(r[f"phi{i}"])]
    if grids:
        h, phi = zip(*grids)
        ax.plot(h, phi, "o-", ms=4, lw=1, label="phi")
        ax.set_xscale("log")
        label_log_ticks(ax, h)
    if math.isfinite(r["phi_extrapolated"]):
        ax.axhline(r["phi_extrapolated"], color="k", ls="--", lw=1, label="extrapolated")
    band = r["uncertainty1"]
    if math.isfinite(band):
        ax.axhspan(r["phi1"] - band, r["phi1"] + band, color="C1", alpha=0.25,
                   label="uncertainty")
    title = f"{r['quantity']}: {gci_order_text(r)}"
    ax.set_title(title if len(title) <= 36 else title.replace(": ", ":\n"), fontsize=8)
    ax.set_xlabel(h_label, fontsize=8)
    ax.set_ylabel(rc.with_units("phi", units_of(r["quantity"])), fontsize=8)
    ax.tick_params(labelsize=7)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.grid(True, which="both", alpha=0.3)


def figure_gci(study, rows):
    """One panel per GCI row of `study`, at most ERROR_PANEL_COLUMNS to a line."""
    fig = plt.figure()
    axes = panel_grid(fig, len(rows), 3.3, 2.9)
    for ax, r in zip(axes, rows):
        gci_panel(ax, r, step_axis(study))
    suptitle(fig, f"{study}: quantities of interest against the {step_axis(study)}")
    rc.legend_above(fig, where="bottom")
    return fig


def phase_text(phase):
    return "all" if math.isnan(phase) else rc.fmt(phase, 3)


def figure_sampling(study, rows):
    """se / se(smallest K) against K for every quantity of one study, with K^-1/2."""
    series = {}
    for r in rows:
        series.setdefault((r["quantity"], r["phase"] if not math.isnan(r["phase"]) else -1.0),
                          []).append(r)
    fig, ax = plt.subplots(figsize=(5.6, 4.2))
    k_all = []
    for (quantity, phase), points in sorted(series.items()):
        points.sort(key=lambda r: r["K"])
        k = np.array([r["effective_K"] for r in points])
        se = np.array([r["standard_error"] for r in points])
        if len(k) == 0 or not (se[0] > 0):
            continue
        keep = se > 0
        label = f"{quantity} (f t {'all' if phase < 0 else rc.fmt(phase, 3)})"
        ax.loglog(k[keep], se[keep] / se[0], "o-", ms=4, lw=1, label=label)
        k_all.extend(r["K"] for r in points)  # nominal K: the ticks
    if k_all:
        ks = np.array([min(k_all), max(k_all)], dtype=float)  # reference line over the K range
        ax.loglog(ks, (ks / ks[0]) ** -0.5, "k--", lw=1.5, label="K^-1/2")
        label_log_ticks(ax, k_all)
    ax.set_xlabel("sampled cycles K (effective) [1]")
    ax.set_ylabel("standard error / its value at the smallest K [1]")
    ax.set_title(textwrap.fill(f"{study}: standard error against K", 60))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6)
    fig.tight_layout()
    return fig


def sampling_fit_line(r, mark):
    band = f"{rc.fmt(r['expected_slope'] - r['band'], 3)}–" \
           f"{rc.fmt(r['expected_slope'] + r['band'], 3)}"
    return (f"| {r['study']} | {r['quantity']} | {phase_text(r['phase'])} | "
            f"{rc.fmt(r['fitted_slope'], 4)} ± {rc.fmt(r['slope_std_error'], 2)} "
            f"({int(r['fit_points'])}) | {rc.fmt(r['expected_slope'])} | {band} | {mark} |")


def sampling_fit_failure(r):
    return (f"sampling {r['study']} / {r['quantity']} / f t {phase_text(r['phase'])}: "
            f"slope {rc.fmt(r['fitted_slope'], 4)} outside "
            f"{rc.fmt(r['expected_slope'])} ± {rc.fmt(r['band'], 3)}")


def relation_of(criterion):
    return {"at_least": ">=", "at_most": "<="}.get(criterion, criterion)


def bin_size_line(r, mark):
    quantity = r["quantity"]
    return rc.table_row([
        r["study"], quantity, units_of(quantity), phase_text(r["phase"]),
        rc.fmt(r["sigma_value"], 5), rc.fmt(r["half_sigma_value"], 5), r["statistic"],
        bin_size_value_units(r), rc.fmt(r["value"], 4),
        f"{relation_of(r['criterion'])} {rc.fmt(r['limit'], 4)}", mark])


def bin_size_failure(r):
    return (f"bin size {r['study']} / {r['quantity']}: {r['statistic']} = "
            f"{rc.fmt(r['value'], 4)}, required {relation_of(r['criterion'])} "
            f"{rc.fmt(r['limit'], 4)}")


def order_line(r, mark):
    fitted = f"{rc.fmt(r['fitted_order'], 4)} ± {rc.fmt(r['order_std_error'], 2)} " \
             f"({int(r['fit_points'])})"
    band = f"{rc.fmt(r['design_order'] - r['tolerance'], 3)}–" \
           f"{rc.fmt(r['design_order'] + r['tolerance'], 3)}"
    return (f"| {r['study']} | {r['field']} | {r['norm']} | {fitted} | "
            f"{rc.fmt(r['pair_order_finest'], 4)} | {rc.fmt(r['pair_order_next'], 4)} | "
            f"{rc.fmt(r['design_order'])} | {band} | {mark} |")


def order_failure(r):
    return (f"order {r['study']} / {r['field']} / {r['norm']}: fitted "
            f"{rc.fmt(r['fitted_order'], 4)}, pairs {rc.fmt(r['pair_order_finest'], 4)}"
            f" and {rc.fmt(r['pair_order_next'], 4)}, design "
            f"{rc.fmt(r['design_order'])} ± {rc.fmt(r['tolerance'])}")


def gci_result_text(r, mark):
    if mark != NOT_CHECKED:
        return f"{mark} (p in {rc.fmt(r['design_order'])} ± {rc.fmt(r['order_tolerance'])})"
    if r["convergence"] == "two-grids":
        return f"{mark} (two grids, assumed p, Fs = 3)"
    return f"{mark} (a diagnostic: the study's claim is its bound check)"


def gci_line(r, mark):
    percent = [rc.fmt(100 * r[k], 3) for k in ("relative_difference21", "gci21", "gci32")]
    return rc.table_row(
        [r["study"], r["quantity"], units_of(r["quantity"])]
        + [rc.fmt(r[k], 6) for k in ("phi1", "phi2", "phi3")]
        + [rc.fmt(r["order"], 4), rc.fmt(r["design_order"]), r["theory"],
           rc.fmt(r["phi_extrapolated"], 6)] + percent
        + [rc.fmt(r["uncertainty1"], 3), r["convergence"], gci_result_text(r, mark)])


def gci_failure(r):
    return (f"GCI {r['study']} / {r['quantity']}: observed order {rc.fmt(r['order'], 4)} "
            f"({r['convergence']}) outside the asymptotic range "
            f"{rc.fmt(r['design_order'])} ± {rc.fmt(r['order_tolerance'])} "
            f"(theory: {r['theory']})")


INTEGRATOR_STUDY = "real-1d-integrator-"


def own_time_error(r, bounds):
    """For a fast integrator's difference from the reference (real-1d-integrator-<setting>):
    the time-step study of the same setting at the same cell (real-time-d1-<setting>), its
    bound row of the same quantity: the measured time error of the setting's production step.
    None for other studies or where that study is not in the input."""
    if not r["study"].startswith(INTEGRATOR_STUDY):
        return None
    study = "real-time-d1-" + r["study"][len(INTEGRATOR_STUDY):]
    return next((b for b in bounds if b["study"] == study and b["quantity"] == r["quantity"]),
                None)


def time_error_cell(r, bounds):
    if not r["study"].startswith(INTEGRATOR_STUDY):
        return ""
    own = own_time_error(r, bounds)
    return rc.fmt(own["value"], 4) if own else "no time-step study"


def bound_line(r, mark, bounds=()):
    ratio = r["value"] / r["bound"] if r["bound"] > 0 else float("nan")
    return rc.table_row(
        [r["study"], r["quantity"], units_of(r["quantity"]), rc.fmt(r["value"], 4),
         r["value_basis"], rc.fmt(r["bound"], 4), r["bound_basis"], rc.fmt(ratio, 3),
         time_error_cell(r, bounds), mark])


def bound_failure(r, gci_rows=(), bounds=()):
    text = (f"bound {r['study']} / {r['quantity']}: {rc.fmt(r['value'], 4)} "
            f"({r['value_basis']}) above {rc.fmt(r['bound'], 4)} ({r['bound_basis']})")
    return text + step_to_meet_the_bound(r, gci_rows) + time_error_explanation(r, bounds)


def time_error_explanation(r, bounds):
    """Whether a fast integrator's failing difference is its own time error: the two runs share
    the grid, so their difference is the difference of their time errors; where the setting's
    measured time error at its step covers the difference, that is the explanation."""
    if not r["study"].startswith(INTEGRATOR_STUDY):
        return ""
    own = own_time_error(r, bounds)
    if own is None:
        return ("; unexplained by measurement: no time-step study of this setting "
                f"(real-time-d1-{r['study'][len(INTEGRATOR_STUDY):]}) in the input")
    if own["value"] >= r["value"]:
        return (f"; explained: this setting's own time error at its step, "
                f"{rc.fmt(own['value'], 4)} ({own['study']}), covers the difference")
    return (f"; not explained by its time error at its step, {rc.fmt(own['value'], 4)} "
            f"({own['study']}), which is smaller than the difference")


def step_to_meet_the_bound(r, gci_rows):
    """What a failing time-step bound would take: the fraction of the production step at which
    the time error, shrinking at the order of the study's step triple (the observed one where
    the triple converges monotonically below the integrator's formal order, the formal one
    otherwise), would equal the bound. Empty for the other studies."""
    triple = next((g for g in gci_rows if r["study"].startswith("real-time-")
                   and g["study"] == r["study"] and g["quantity"] == r["quantity"]), None)
    if triple is None or not r["bound"] > 0:
        return ""
    formal = triple["design_order"]
    observed = triple["order"]
    if triple["convergence"] == "monotonic" and observed < 0:
        return "; no step is estimated: its changes grow as the step shrinks"
    slower = triple["convergence"] == "monotonic" and 0 < observed < formal
    order = observed if slower else formal
    fraction = (r["bound"] / r["value"]) ** (1.0 / order)
    return (f"; it would take a step of {rc.fmt(fraction, 2)} of the production step "
            f"(the error shrinking at the {'observed' if slower else 'formal'} temporal order "
            f"{rc.fmt(order, 3)})")


def bound_section(data, failures):
    """The studies' error-within-uncertainty claims; returns (lines, checks)."""
    rows = sorted(data["bounds"], key=lambda r: (r["study"], r["quantity"]))
    if not rows:
        return [], 0
    table, checks = judged_table(
        "| study | quantity | units | value | value basis | bound | bound basis | "
        "value / bound [1] | time error of this integrator at its step | result |", rows,
        lambda r, mark: bound_line(r, mark, data["bounds"]),
        lambda r: bound_failure(r, data["gci"], data["bounds"]), failures,
        "no bound checks found")
    return ["## Errors within their uncertainty", "",
            "Each row: an error of the study (value) and the uncertainty it must not exceed "
            "(bound), in the units of the row; the time-step studies compare the time error of "
            "the production step with the grid error at the production cell. For a fast "
            "integrator (real-1d-integrator-*), whose difference from the reference at cell 0.1 "
            "is the difference of the two settings' time errors (same grid), the column 'time "
            "error of this integrator at its step' gives that setting's time error measured by "
            "its time-step study (real-time-d1-*, same quantity; the row's value there): a "
            "failing difference that this time error covers is explained by it.", ""] + table, \
        checks


def awaiting_section(data):
    """The bound checks a former judge computed, kept for information until the nightly reruns
    their studies; not checks of this report."""
    rows = sorted(data["awaiting-bounds"], key=lambda r: (r["study"], r["quantity"]))
    if not rows:
        return []
    former = {1: "former: pass", 0: "former: fail"}
    header = ("| study | quantity | units | value | value basis | bound | bound basis | "
              "value / bound [1] | time error of this integrator at its step | "
              "former verdict |")
    lines = ["## Bound checks awaiting a rerun", "",
             f"Tables in {AWAITING_RERUN}/: computed with a former rule for the grid uncertainty "
             "and the time error, or under a former protocol of the studies (a transient too short "
             "for the periodic state, so that the sampled cycle was still relaxing; "
             "verification/README.md), "
             "and not counted in this report's checks. The nightly rerun "
             "of their studies replaces them; until then their former verdicts are shown for "
             "information.", "", header, "|---" * (header.count("|") - 1) + "|"]
    lines += [bound_line(r, former.get(r["pass"], "not checked"), data["bounds"]) for r in rows]
    return lines + [""]


def known_failure_section(repository):
    """Why each failing study fails: the reason of every known-failure line of the status
    files beside the tests (verification/README.md, "status.txt"), with its test pattern."""
    lines = [(os.path.relpath(path, repository), pattern, reason)
             for path, _, pattern, labels, reason in rc.status_lines(repository)
             if labels and "known-failure" in labels]
    if not lines:
        return []
    out = ["## Known failures and why", "",
           "The tests that fail on purpose, as their status files state it: which claim the "
           "project does not meet, by how much, and why (details in verification/README.md).",
           "", "| status file | tests | why |", "|---|---|---|"]
    out += [rc.table_row([f"`{path}`", f"`{pattern}`", reason])
            for path, pattern, reason in lines]
    return out + [""]


def order_section(data, failures):
    """The observed orders against the design order; returns (lines, checks)."""
    rows = sorted(data["orders"], key=lambda r: (r["study"], r["field"],
                                                 NORM_ORDER.get(r["norm"], 9)))
    table, checks = judged_table(
        "| study | field | norm | fitted p (± s.e., points) [1] | p finest pair [1] | "
        "p next pair [1] | design [1] | band [1] | result |", rows, order_line, order_failure,
        failures, "no order checks found")
    return ["## Observed orders against the design order", ""] + table, checks


def gci_section(data, out_dir, failures, orders):
    """The GCI of the quantities of interest, then a figure per study; returns (lines, checks)."""
    rows = sorted(data["gci"], key=lambda r: (r["study"], r["quantity"]))
    for r in rows:
        r["theory"] = theory_of(r, orders)[1]
    table, checks = judged_table(
        "| study | quantity | units | phi1 (fine) | phi2 | phi3 | p [1] | theoretical p [1] | "
        "reason | phi extrapolated | "
        "e21 [%] | GCI21 [%] | GCI32 [%] | uncertainty of phi1 | convergence | result |",
        rows, gci_line, gci_failure, failures, "no GCI studies found")
    plots = []
    for study in dict.fromkeys(r["study"] for r in rows):
        # "-gci": a study may also have an error table, whose plot takes the plain name.
        name = rc.write_figure(figure_gci(study, [r for r in rows if r["study"] == study]),
                               out_dir, f"convergence-{safe_name(study)}-gci.png")
        plots += [f"![{study}]({name})", ""]
    return ["## Grid convergence index of the quantities of interest", "",
            "Each row is judged against its quantity's theoretical order (column "
            "'theoretical p'): for the real problem's grid triples the order theory allows that "
            f"quantity, declared with the short name of its reason in "
            f"{THEORETICAL_ORDERS} and explained in {THEORY_SECTION} "
            "(Engquist and Sjogreen 1998 and Casper and Carpenter 1998 on why a captured shock "
            "would limit it to first order, and why these grids resolve the shock instead); for "
            "a time-step study's own rows the integrator's temporal order. "
            "GCI in percent of the fine-grid value (Fs = 1.25, the observed order); the "
            "uncertainty of phi1 in the units of its row: the GCI with Fs 1.25 where the grids "
            "are in the asymptotic range (monotonic, observed order within the band of the "
            "design order), Fs 3 with the order held within [0.5, design order] where they are "
            "not, at least half the range of the three values where they do not converge "
            "monotonically (Oberkampf and Roy 2010, section 8.6; Stern et al. 2001). The "
            "figures: phi against h (the step scale of a time-step study), dashed the "
            "extrapolated value, shaded the band phi1 ± its uncertainty.",
            ""] + table + plots, checks


def sampling_section(data, out_dir, failures):
    """The MD sampling study: slope fits, the se table, bin size; returns (lines, checks)."""
    lines = ["## MD sampling convergence", "",
             "Standard error of MD fields and quantities of interest against the number K of "
             "sampled cycles (expected slope -1/2 of ln se against ln K, band from the degrees "
             "of freedom of each standard error), and the bin size sigma against sigma/2.", ""]
    fits = sorted(data["sampling-fit"],
                  key=lambda r: (r["study"], r["quantity"],
                                 -1 if math.isnan(r["phase"]) else r["phase"]))
    fit_table, fit_checks = judged_table(
        "| study | quantity | f t [1] | fitted slope (± s.e., points) [1] | expected [1] | "
        "band [1] | result |",
        fits, sampling_fit_line, sampling_fit_failure, failures, "no MD sampling studies found")
    lines += fit_table

    by_study = {}
    for r in data["sampling"]:
        by_study.setdefault(r["study"], []).append(r)
    for study in sorted(by_study):
        rows = by_study[study]
        ks = sorted({int(r["K"]) for r in rows})
        lines += [f"### {study}: standard error against K", "",
                  "| quantity | units | f t [1] | " + " | ".join(f"K = {k}" for k in ks) + " |",
                  "|---|---|---" + "|---" * len(ks) + "|"]

        def key(r):  # nan (all phases) never equals itself: -1 stands for it
            return (r["quantity"], -1.0 if math.isnan(r["phase"]) else r["phase"])
        for quantity, phase in sorted({key(r) for r in rows}):
            cells = {int(r["K"]): r["standard_error"] for r in rows if key(r) == (quantity, phase)}
            # The same cycles at every K: the largest count is the number of cycles without one.
            missing = max(r["missing"] for r in rows if key(r) == (quantity, phase))
            note = f" ({int(missing)} cycles without a value)" if missing else ""
            lines.append(f"| {quantity}{note} | {units_of(quantity)} | "
                         f"{phase_text(phase if phase >= 0 else math.nan)} | "
                         + " | ".join(rc.fmt(cells.get(k, float("nan"))) for k in ks) + " |")
        name = rc.write_figure(figure_sampling(study, rows), out_dir,
                               f"sampling-{safe_name(study)}.png")
        lines += ["", f"![{study}: se against K]({name})", ""]

    bins = sorted(data["bin-size"], key=lambda r: (r["study"], r["quantity"]))
    bin_table, bin_checks = judged_table(
        "| study | quantity | units | f t [1] | sigma | sigma/2 | statistic | value units | "
        "value | criterion | result |",
        bins, bin_size_line, bin_size_failure, failures, "no bin-size checks found")
    lines += ["### Bin size: sigma against sigma/2", "",
              "sigma and sigma/2: the quantity at the two bin sizes, in its units; value and "
              "criterion in the value units.", ""] + bin_table
    return lines, fit_checks + bin_checks


def term_share_tables(rows):
    """One table per study: each term's share of the manufactured source per equation."""
    if not rows:
        return []
    lines = ["## Term shares of the manufactured sources", "",
             "Each term's part of the source (root mean square over the cell centres of the "
             "coarsest grid at three times in [0, t_end]) as a share of the sum of every term's "
             "part in that equation [1]; a blank cell: the term does not enter the equation. "
             "MmsTermShares3D requires every term's largest share to be at least 0.01.", ""]
    for study in sorted({r["study"] for r in rows}):
        mine = [r for r in rows if r["study"] == study]
        equations = list(dict.fromkeys(r["equation"] for r in mine))
        lines += [f"### {study}: term shares", "",
                  "| term | " + " | ".join(equations) + " |", "|---" * (1 + len(equations)) + "|"]
        for term in dict.fromkeys(r["term"] for r in mine):
            share = {r["equation"]: r["share"] for r in mine if r["term"] == term}
            lines.append(f"| {term} | " + " | ".join(
                rc.fmt(share[e], 3) if e in share else "" for e in equations) + " |")
        lines.append("")
    return lines


def error_tables(series):
    lines = ["## Errors per level", "",
             "Error norms in the units of their field; h is the cell size [sigma] of a spatial "
             "study, the time step [sqrt(sigma/g)] of a temporal one.", ""] if series else []
    for study in sorted(series):
        hs = sorted({r["h"] for rows in series[study].values() for r in rows}, reverse=True)
        lines += [f"### {study}: errors", "",
                  "| field | units | norm | " + " | ".join(f"h = {rc.fmt(h)}" for h in hs) +
                  " | " + " | ".join(f"p({i}-{i + 1}) [1]" for i in range(len(hs) - 1)) + " |",
                  "|---" * (3 + 2 * len(hs) - 1) + "|"]
        keys = sorted(series[study], key=lambda k: (k[0], NORM_ORDER.get(k[1], 9)))
        for field, norm in keys:
            rows = series[study][(field, norm)]
            by_h = {r["h"]: r["error"] for r in rows}
            orders = pair_orders(rows)
            cells = [rc.fmt(by_h.get(h, float("nan"))) for h in hs]
            cells += [rc.fmt(p, 3) for p in orders] + [""] * (len(hs) - 1 - len(orders))
            lines.append(f"| {field} | {units_of(field)} | {norm} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--input", required=True, help="directory of *.errors/orders/gci.csv")
    parser.add_argument("--output", help="default: reports/convergence.md of the repository")
    parser.add_argument("--build-dir", help="build directory (its CMakeCache gives the build type)")
    parser.add_argument("--build-type", help="overrides the build type read from --build-dir")
    parser.add_argument("--commit", help="defaults to git rev-parse HEAD of this repository")
    parser.add_argument("--strict", action="store_true", help="exit 1 when any check fails")
    parser.add_argument("--theoretical-orders",
                        help="table quantity,order,reason of the real problem's quantities "
                        f"(default: {THEORETICAL_ORDERS} of the repository)")
    add_repository_option(parser)
    args = parser.parse_args(argv)
    repository = repository_argument(parser, args)
    args.output = args.output or os.path.join(repository, "reports", "convergence.md")
    args.theoretical_orders = (args.theoretical_orders
                               or os.path.join(repository, THEORETICAL_ORDERS))

    if not os.path.isdir(args.input):
        print(f"make_convergence_report: --input {args.input} is not a directory", file=sys.stderr)
        return 2
    try:
        data, files = read_inputs(args.input)
        orders = read_theoretical_orders(args.theoretical_orders)
        for row in data["gci"]:  # every row judged at its order before anything is written
            theory_of(row, orders)
    except InputProblem as problem:
        print(f"make_convergence_report: {problem}", file=sys.stderr)
        return 2

    out_dir = os.path.dirname(os.path.abspath(args.output))
    commit = args.commit or rc.git_commit(repository)
    build_type = args.build_type or rc.build_type_of(args.build_dir)

    failures = []
    order_lines, order_checks = order_section(data, failures)
    gci_lines, gci_checks = gci_section(data, out_dir, failures, orders)
    bound_lines, bound_checks = bound_section(data, failures)
    sampling_lines, sampling_checks = sampling_section(data, out_dir, failures)

    series = series_of(data["errors"])
    plot_lines = ["## Plots", ""]
    for study in sorted(series):
        designs = {r["design_order"] for r in data["orders"] if r["study"] == study}
        name = rc.write_figure(figure_errors(study, series[study], designs), out_dir,
                               f"convergence-{safe_name(study)}.png")
        plot_lines += [f"![{study}]({name})", ""]

    checks = order_checks + gci_checks + bound_checks + sampling_checks
    lines = ["# Convergence report", "",
             f"- commit: {commit}",
             f"- date: {rc.utc_now()}",
             f"- machine: {rc.machine_description()}",
             f"- build type: {build_type}",
             f"- input: {rc.repository_path(args.input, repository)} ({len(files)} files)", "",
             "## Summary", "",
             f"{checks} checks: {checks - len(failures)} pass, {len(failures)} fail."]
    if not files:
        lines.append("No error tables or study summaries were found in the input directory.")
    if failures:
        lines += ["", "Failing checks (measured values):", ""] + [f"- {f}" for f in failures]
    lines.append("")
    lines += known_failure_section(repository)
    lines += (order_lines + gci_lines + bound_lines + awaiting_section(data) + sampling_lines +
              term_share_tables(data["term-shares"]) + error_tables(series) + plot_lines)
    tables = os.path.join(out_dir, TABLES_DIRECTORY)
    lines += ["## Input files", "",
              f"Copied beside this report into {TABLES_DIRECTORY}/ (the validation report reads "
              "the real-problem GCI table from there).", ""] + [f"- {f}" for f in files] + [""]
    copy_tables(args.input, files, tables)
    text = "\n".join(lines)
    rc.write_text_atomically(args.output, text)
    remove_stale_plots(out_dir, text)
    print(f"wrote {args.output}: {checks} checks, {len(failures)} failing")
    return 1 if (args.strict and failures) else 0


if __name__ == "__main__":
    sys.exit(main())
