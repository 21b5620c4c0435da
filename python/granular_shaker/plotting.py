"""Figures of runs and analyses. Each function returns a matplotlib Figure whose axes carry
one quantity each, labelled with its units, a legend naming what is drawn (the plate
included), and a colorbar where colour carries a value. Pass `figure` to draw into one of
your own; otherwise a new Figure is made (pyplot is not used, so no window opens)."""
import numpy as np
from matplotlib.figure import Figure

DESCRIPTIONS = {"n": "number density n", "nu": "volume fraction nu", "uz": "vertical velocity u_z",
                "T": "granular temperature T"}
_PLATE_FRAME = {"uz": "vertical velocity u_z - v_p"}
# Bins whose density is below this fraction of the largest are left out of the automatic
# height range (the MD box reaches 200 sigma; the layer's gas ends far below).
_MATERIAL_FRACTION = 1e-2


def height_label(frame, units="sigma"):
    return f"height z [{units}]" if frame == "lab" else f"height above the plate z - z_p [{units}]"


PHASE_LABEL = "phase f t [cycles]"
_SOLVER_NAMES = {"md": "MD", "continuum": "continuum"}


def profile_label(run, quantity):
    description = (_PLATE_FRAME.get(quantity) if run.frame == "plate" else None) \
        or DESCRIPTIONS.get(quantity, quantity)
    return run.profiles.label(quantity, description)


def plot_profiles(run, quantities=("n", "T"), phases=(0.0, 0.25, 0.5, 0.75), zmax=None,
                  figure=None):
    """Profiles against height, one axis per quantity, a line per phase (the stored phases
    nearest `phases`) and the plate's height at that phase; for MD a band of one standard
    error."""
    figure = figure or Figure(figsize=(10, 0.5 + 3.5 * len(quantities)), layout="constrained")
    axes = figure.subplots(len(quantities), 1, squeeze=False)[:, 0]
    rows = [_row_of(run, phase) for phase in phases]
    for ax, quantity in zip(axes, quantities):
        for row, colour in zip(rows, _colours(len(rows))):
            phase = f"f t = {run.profiles['phase'][row]:.3g}"
            _draw_profile(ax, run, quantity, row, colour, f"{_solver_name(run)}, {phase}")
            ax.axvline(run.plate_height()[row], color=colour, linestyle=":",
                       label=f"plate, {phase} (dotted)")
        ax.set_xlabel(height_label(run.frame, run.profiles.units["z"]))
        ax.set_ylabel(profile_label(run, quantity))
        ax.set_xlim(*_height_range(run, rows, zmax))
        # Beside the axes, where it hides no data.
        ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0))
    return figure


def plot_center_of_mass_and_shock(analyses, figure=None):
    """Centre of mass (with standard errors where the analysis has them) and shock location
    against phase, with the plate, from one `read_analysis_json` result or a list of them."""
    analyses = analyses if isinstance(analyses, (list, tuple)) else [analyses]
    figure = figure or Figure(figsize=(7, 4), layout="constrained")
    ax = figure.subplots()
    for analysis, colour in zip(analyses, _colours(len(analyses))):
        name = _SOLVER_NAMES.get(analysis.attributes.get("solver"), "run")
        com, shock = analysis.per_phase["center_of_mass"], analysis.per_phase["shock_location"]
        ax.errorbar(analysis.phase, com.value, yerr=_finite_or_none(com.error), color=colour,
                    marker=".", capsize=2, label=f"centre of mass ({name})")
        ax.plot(analysis.phase, shock.value, color=colour, marker="v", linestyle="--",
                label=f"shock location ({name})")
    plate = analyses[0].plate_z if analyses[0].frame == "lab" else 0 * analyses[0].phase
    ax.plot(analyses[0].phase, plate, color="black", linewidth=2, label="plate")
    ax.set_xlabel(PHASE_LABEL)
    ax.set_ylabel(height_label(analyses[0].frame, com.unit))
    ax.legend(fontsize="small")
    return figure


def plot_space_time(run, quantity="nu", zmax=None, figure=None):
    """A space-time map: height against phase, colour the quantity, with the plate."""
    figure = figure or Figure(figsize=(7, 4.5), layout="constrained")
    ax = figure.subplots()
    p = run.profiles
    phase_edges, z_edges = _space_time_edges(p["phase"], p["z"], p["bin_height"])
    mesh = ax.pcolormesh(phase_edges, z_edges, p[quantity], shading="flat", cmap="viridis")
    ax.plot(p["phase"], run.plate_height(), color="red", linewidth=2, label="plate")
    ax.set_ylim(*_height_range(run, range(len(p["phase"])), zmax))
    ax.set_xlabel(PHASE_LABEL)
    ax.set_ylabel(height_label(run.frame, p.units["z"]))
    ax.legend(loc="upper right", fontsize="small",
              title=f"{_solver_name(run)}: colour is {DESCRIPTIONS.get(quantity, quantity)}")
    figure.colorbar(mesh, ax=ax, label=profile_label(run, quantity))
    return figure


def plot_md_against_continuum(md, continuum, quantity="n", phases=(0.0, 0.25, 0.5, 0.75),
                              zmax=None, figure=None):
    """One axis per phase: the MD profile with its standard-error band, the continuum's, and
    the plate. Both runs must be in the same frame and store the requested phases."""
    if md.frame != continuum.frame:
        raise ValueError(f"the MD run is in the {md.frame} frame, the continuum run in the "
                         f"{continuum.frame} frame: read both in the same frame")
    figure = figure or Figure(figsize=(4 * len(phases), 3.5), layout="constrained")
    axes = figure.subplots(1, len(phases), squeeze=False)[0]
    for ax, phase in zip(axes, phases):
        md_row, continuum_row = _row_of(md, phase), _row_of(continuum, phase)
        md_phase = md.profiles["phase"][md_row]
        continuum_phase = continuum.profiles["phase"][continuum_row]
        if abs(md_phase - continuum_phase) > 1e-9:
            raise ValueError(f"no common stored phase near f t = {phase}: MD has {md_phase}, "
                             f"the continuum {continuum_phase}")
        _draw_profile(ax, md, quantity, md_row, "tab:blue", "MD")
        _draw_profile(ax, continuum, quantity, continuum_row, "tab:orange", "continuum")
        ax.axvline(md.plate_height()[md_row], color="black", linestyle=":", label="plate")
        ax.set_title(f"f t = {md_phase:.3g}")
        ax.set_xlabel(height_label(md.frame, md.profiles.units["z"]))
        ax.set_ylabel(profile_label(md, quantity))
        ax.set_xlim(*_height_range(md, [md_row], zmax))
        ax.legend(fontsize="small")
    return figure


def _draw_profile(ax, run, quantity, row, colour, label):
    """The profile at `row`, and where the run has standard errors (MD) a band of one."""
    p = run.profiles
    z, values = p["z"][row], p[quantity][row]
    ax.plot(z, values, color=colour, label=label)
    error = p.get(f"{quantity}_se")
    if error is not None:
        ax.fill_between(z, values - error[row], values + error[row], color=colour, alpha=0.25,
                        linewidth=0, label=f"{label}: ± 1 standard error (shaded)")


def _space_time_edges(phase, z, bin_height):
    """Corners of the map's cells, (K + 1) x (B + 1): phases midway between the stored phases
    k / K, and the bin edges' heights there midway between the two phases' (a continuum row's
    cells move with the plate, so its cells are quadrilaterals that follow it)."""
    half = 0.5 / len(phase)
    phase_edges = np.append(phase - half, phase[-1] + half)
    edges = np.concatenate([z - bin_height[:, None] / 2, z[:, -1:] + bin_height[:, None] / 2],
                           axis=1)
    z_edges = np.concatenate([edges[:1], (edges[1:] + edges[:-1]) / 2, edges[-1:]])
    return np.broadcast_to(phase_edges[:, None], z_edges.shape), z_edges


def _row_of(run, phase):
    """The stored phase nearest `phase` (cyclically)."""
    distance = np.abs((run.profiles["phase"] - phase + 0.5) % 1.0 - 0.5)
    return int(np.argmin(distance))


def _height_range(run, rows, zmax):
    """From below the plate's lowest point to `zmax`, or to the top of the material."""
    p = run.profiles
    rows = list(rows)
    bottom = min(0.0, float(np.min(run.plate_height()[rows])))
    if zmax is None:
        n = p["n"][rows]
        material = n > _MATERIAL_FRACTION * np.nanmax(n)
        zmax = float(np.max(p["z"][rows][material])) if material.any() else float(p["z"].max())
    return bottom - 1.0, zmax + 1.0


def _solver_name(run):
    return _SOLVER_NAMES.get(run.solver, run.solver)


def _colours(count):
    return [f"C{i % 10}" for i in range(count)]


def _finite_or_none(errors):
    errors = np.asarray(errors, dtype=float)
    return errors if np.isfinite(errors).any() else None
