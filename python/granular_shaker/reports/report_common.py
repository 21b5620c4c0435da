"""Helpers shared by the report generators: provenance header, atomic file writes and the
units of table headers.

Nothing under a final output name is ever half-written: text and figures go to a temporary
name in the same directory and are renamed into place.
"""
import csv
import datetime
import math
import os
import platform
import re
import subprocess
import sys
import tempfile

import numpy as np


def git_commit(repository):
    try:
        out = subprocess.run(["git", "-C", repository, "rev-parse", "HEAD"], check=True,
                             capture_output=True, text=True)
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def repository_path(path, repository):
    """How a report names an input: relative to the repository root when it is inside the
    repository, else only its last component, marked as outside (a report never carries an
    absolute path of the machine it was written on)."""
    root = os.path.realpath(repository)
    full = os.path.realpath(path)
    if os.path.commonpath([root, full]) == root:
        return os.path.relpath(full, root)
    return f"{os.path.basename(full.rstrip(os.sep)) or full} (outside the repository)"


def machine_description():
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return (f"{platform.node()} ({cpu}, {os.cpu_count()} cores, "
            f"{platform.system()} {platform.release()})")


def build_type_of(build_dir):
    """CMAKE_BUILD_TYPE from a build directory's CMakeCache.txt, or 'unknown'."""
    if not build_dir:
        return "unknown"
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt")) as f:
            for line in f:
                if line.startswith("CMAKE_BUILD_TYPE:"):
                    return line.split("=", 1)[1].strip() or "unknown"
    except OSError:
        pass
    return "unknown"


def utc_now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")


def readable_mode():
    """The mode a plain open() would give a new file (mkstemp's files are private: 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_text_atomically(path, text):
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fd, temporary = tempfile.mkstemp(dir=directory, prefix=".partial-", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.chmod(temporary, readable_mode())
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


def save_figure_atomically(figure, path, dpi=90):
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fd, temporary = tempfile.mkstemp(dir=directory, prefix=".partial-", suffix=".png")
    os.close(fd)
    try:
        figure.savefig(temporary, dpi=dpi, format="png")
        os.chmod(temporary, readable_mode())
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


# ---- figures --------------------------------------------------------------------------------
# Every figure follows figure_rules.py: units on both axes, MD drawn with its standard
# errors, a legend naming everything drawn, a colorbar for a colour that carries a value.

MD_STYLE = dict(marker="o", ms=3, ls="none", capsize=0, elinewidth=0.8)
CONTINUUM_STYLE = dict(ls="-", lw=1.2)
SOLVER_LABELS = {"md": "MD (± standard error)", "continuum": "continuum"}
NU_PER_N = math.pi / 6  # nu = (pi/6) n (docs/analysis.md), so se(nu) = (pi/6) se(n)


def read_shaker_csv(path):
    """A CSV of `shaker analyze` (--csv, --profiles-csv, --patterns), whose header names each
    column with its units in brackets ("z [sigma]"; a column of words, such as a symmetry class,
    has none): {name: array}, {name: units}. Numeric columns are float arrays, others arrays of
    str."""
    with open(path, newline="") as f:
        header, *rows = list(csv.reader(f))
    names, units = [], {}
    for cell in header:
        name, _, unit = cell.partition(" [")
        names.append(name)
        units[name] = unit.rstrip("]")
    columns = {}
    for i, name in enumerate(names):
        values = [row[i] for row in rows]
        try:
            columns[name] = np.array([float(v) for v in values], dtype=float)
        except ValueError:
            columns[name] = np.array(values)
    return columns, units


def profile_errors(profiles, k):
    """The MD run file's standard errors of nu and T at stored phase k (n_se, T_se,
    docs/output-schema.md), None where the run file has none (a continuum run)."""
    if "n_se" not in profiles:
        return {"nu": None, "T": None}
    return {"nu": NU_PER_N * profiles["n_se"][k], "T": profiles["T_se"][k]}


def draw_profile(ax, solver, value, z, error=None, label=None):
    """A field against height: MD as points with horizontal standard-error bars, the continuum
    as a line."""
    label = label or SOLVER_LABELS[solver]
    if solver == "md":
        return ax.errorbar(value, z, xerr=error, label=label, **MD_STYLE)
    return ax.plot(value, z, label=label, **CONTINUUM_STYLE)


def draw_series(ax, solver, x, y, error=None, label=None, **style):
    """A quantity against phase: MD as points with vertical standard-error bars (where the
    analysis gives them), the continuum as a line."""
    if solver == "md":
        return ax.errorbar(x, y, yerr=error, label=label, **{**MD_STYLE, **style})
    return ax.plot(x, y, label=label, **{**CONTINUUM_STYLE, **style})


def legend_above(fig, columns=4, fontsize=8, where="top"):
    """One legend for every panel, above them (below them, where="bottom", for a figure with a
    title): each label drawn in any axes, once. Lays the figure out leaving it room."""
    handles = {}
    for ax in fig.axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, handle)
    columns = min(columns, len(handles)) or 1
    room = (0.25 * -(-len(handles) // columns) + 0.15) / fig.get_figheight()
    top = where == "top"
    fig.tight_layout(rect=(0, 0, 1, 1 - room) if top else (0, room, 1, 1))
    fig.legend(handles.values(), handles.keys(), loc="upper center" if top else "lower center",
               ncol=columns, fontsize=fontsize, frameon=False)


def write_figure(figure, out_dir, name):
    """Writes a laid-out figure as out_dir/name (atomically) and closes it; returns name.
    What breaks the rules of figure_rules.py (data the tests did not foresee: a legend on the
    points, a label too long) is named on stderr; the figure is written all the same."""
    import matplotlib.pyplot as plt  # only the generators that draw need matplotlib

    from granular_shaker.reports import figure_rules
    for problem in figure_rules.figure_problems(figure):
        print(f"{name}: not fit to publish: {problem}", file=sys.stderr)
    save_figure_atomically(figure, os.path.join(out_dir, name))
    plt.close(figure)
    return name


def fmt(x, digits=4):
    """A number for a markdown cell; NaN and missing values print as 'n/a'."""
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "n/a"
    if x != x:
        return "n/a"
    return f"{x:.{digits}g}"


# ---- units in tables ------------------------------------------------------------------------
# Every number a report shows has its units in the table (docs/units.md gives the vocabulary:
# sigma, sqrt(sigma/g), sqrt(g sigma), g sigma, 1/sigma^3, ..., "1" for a dimensionless
# number). A column holding one quantity says them in its header, `label [units]`; a table
# whose rows hold different quantities has a column headed UNITS_COLUMN instead.

DIMENSIONLESS = "1"
UNITS_COLUMN = "units"

# The quantities of `shaker analyze` that reports show (per-phase columns of its --csv table,
# per-run values of its --json), with the units its --json gives them (declared beside each
# in solvers/analysis/run_analysis.cpp; validation.report_pipeline checks that they agree).
ANALYSIS_UNITS = {
    "phase": DIMENSIONLESS,  # f t
    "plate_z": "sigma",
    "layer_bottom": "sigma",
    "layer_top": "sigma",
    "center_of_mass": "sigma",
    "shock_location": "sigma",
    "shock_width": "sigma",
    "width_over_mfp": DIMENSIONLESS,
    "front_width_over_mfp": DIMENSIONLESS,
    "max_mach": DIMENSIONLESS,
    "shock_speed": "sqrt(g sigma)",  # plate frame
    "center_of_mass_mean": "sigma",
    "center_of_mass_apex": "sigma",
    # per-run shock quantities
    "formation_phase": DIMENSIONLESS,  # f t
    "exit_phase": DIMENSIONLESS,  # f t
    "lifetime": "1/f",
    "shock_width_mean": "sigma",
    "width_over_mfp_mean": DIMENSIONLESS,
    "max_mach_peak": DIMENSIONLESS,
}


class UnknownUnits(Exception):
    """A report was asked for the units of a name that has none declared: an error, so that a
    new quantity cannot reach a table with a blank where its units belong."""


def units_of(declared, name, what="quantity"):
    """The units `declared` (a dict keyed by name) gives `name`; UnknownUnits if none."""
    try:
        return declared[name]
    except KeyError:
        raise UnknownUnits(f"no units declared for the {what} '{name}'") from None


def with_units(label, units):
    """The header cell of a column holding one quantity."""
    return f"{label} [{units}]"


def analysis_header(label, name):
    """The header cell of a column showing the `shaker analyze` quantity `name`."""
    return with_units(label, units_of(ANALYSIS_UNITS, name, "analysis quantity"))


def table_head(cells):
    """The header line and the separator line of a markdown table with these header cells."""
    return [table_row(cells), table_row("---" for _ in cells)]


def table_row(cells):
    """One line of a markdown table; a '|' inside a cell (an absolute value such as
    |3D - 1D|) is escaped, so that it does not end the cell."""
    return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"


STATUS_LINE = re.compile(r"^(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S.*)$")


def status_lines(source_dir):
    """Every line of every status.txt under source_dir (verification/README.md, "status.txt"),
    in file order, as (path, line number, pattern, labels, reason); pattern, labels and reason
    are None for a line that does not have the five fields. Labels: sorted, [] for default."""
    lines = []
    for root, dirs, files in os.walk(source_dir):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".") and not d.startswith("build"))
        if "status.txt" not in files:
            continue
        path = os.path.join(root, "status.txt")
        with open(path) as f:
            for number, text in enumerate(f, 1):
                if not text.strip() or text.lstrip().startswith("#"):
                    continue
                match = STATUS_LINE.match(text.rstrip("\n"))
                if not match:
                    lines.append((path, number, None, None, None))
                    continue
                labels = [] if match[2] == "default" else sorted(match[2].split(","))
                lines.append((path, number, match[1], labels, match[5]))
    return lines
