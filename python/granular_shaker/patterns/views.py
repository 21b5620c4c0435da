"""What the pattern report shows of a run: the layer seen from above at the stored phases of
one cycle, and the power of its Fourier modes along the box.

The field is the column mass (1/sigma^2) on a horizontal grid, as `shaker analyze --patterns`
defines it (docs/analysis.md, "Patterns"): the MD's particles binned on cells about `cell`
wide (RUN.particles.h5), the continuum's density summed over each column on its own cells
(RUN.fields.h5). The spectrum is that of the column mass averaged across the box's short side,
so that mode m along x has wavelength Lx / m: |c_m|^2 / c_0^2 per frame, and over the frames
at one phase its mean with the standard error of that mean (consecutive cycles: a lower bound
of the error where the pattern drifts slowly).
"""
import os

import numpy as np

from ..fields import read_fields
from ..snapshots import read_snapshots

MODES = 16        # the spectrum's modes m = 1..MODES (wavelengths down to Lx / 16)
DIGITS = 4        # significant digits kept in the results file


def column_mass_frames(run_path, cell=2.0):
    """(cycle, phase, fields [frame, x, y] in 1/sigma^2, (Lx, Ly)) of a run's stored frames."""
    base = os.path.splitext(str(run_path))[0]
    if os.path.exists(base + ".particles.h5"):
        snapshots = read_snapshots(base + ".particles.h5")
        lx, ly = (float(e) for e in snapshots.box_edges[:2])
        nx, ny = (max(2, int(round(length / cell))) for length in (lx, ly))
        area = lx * ly / (nx * ny)
        fields = np.stack([np.histogram2d(p[:, 0] % lx, p[:, 1] % ly, bins=(nx, ny),
                                          range=((0.0, lx), (0.0, ly)))[0] / area
                           for p in snapshots.frames["position"]])
        frames = snapshots.frames
        return (np.asarray(frames["cycle"], float), phase_of(frames["phase"]), fields, (lx, ly))
    fields = read_fields(base + ".fields.h5", names=("n",))
    density = fields.snapshots["n"]                      # frame, z, y, x
    nz, ny, nx = density.shape[1:]
    columns = density.sum(axis=1).transpose(0, 2, 1) * fields.cell_size
    return (np.asarray(fields.snapshots["cycle"], float), phase_of(fields.snapshots["phase"]),
            columns, (nx * fields.cell_size, ny * fields.cell_size))


def phase_of(phases):
    # A frame that closes a cycle may be stored at phase 0.9999999999: it is phase 0.
    return np.round(np.asarray(phases, float) % 1.0, 6) % 1.0


def mode_amplitudes(fields, modes):
    """|c_m| / c_0 of each frame's column mass (fields [frame, x, y]) averaged over y, the
    Fourier modes m = 1..modes along x."""
    spectrum = np.abs(np.fft.rfft(fields.mean(axis=2), axis=1))
    return spectrum[:, 1:modes + 1] / spectrum[:, :1]


def mode_power(fields, modes=MODES):
    """|c_m|^2 / c_0^2 of each frame's column mass averaged over y, m = 1..modes, or up to the
    last mode below the grid's Nyquist mode when it holds fewer."""
    cells = fields.shape[1]
    if cells < 4:
        raise ValueError(f"{cells} cells along x cannot hold a mode")
    return mode_amplitudes(fields, min(modes, (cells - 1) // 2)) ** 2


def last_cycle_views(cycle, phase, fields):
    """{phase: field} at every stored phase of the last cycle that has them all."""
    phases = np.unique(phase)
    complete = [c for c in np.unique(cycle) if all(((cycle == c) & (phase == p)).any()
                                                   for p in phases)]
    if not complete:
        raise ValueError("no cycle holds a frame at every stored phase")
    last = complete[-1]
    return float(last), {float(p): fields[(cycle == last) & (phase == p)][0] for p in phases}


def spectrum_at(phase, power, which):
    """Mean power per mode over the frames at phase `which`, and its standard error (nan with
    one frame)."""
    at = power[phase == which]
    if len(at) < 2:
        return at.mean(axis=0), np.full(at.shape[1], np.nan)
    return at.mean(axis=0), at.std(axis=0, ddof=1) / np.sqrt(len(at))


def phase_spectra(frames):
    """The box length and, at each stored phase, the mean power of each mode over the frames
    at that phase with its standard error (spectrum_at): the structure factor along the box."""
    cycle, phase, fields, (lx, ly) = frames
    power = mode_power(fields)
    spectra = {f"{p:g}": spectrum_at(phase, power, p) for p in np.unique(phase)}
    return dict(box_length=lx, power={p: s[0] for p, s in spectra.items()},
                power_error={p: s[1] for p, s in spectra.items()})


def run_view(frames, which="all"):
    """The view of one run for the results file, from its column mass (column_mass_frames):
    the last complete cycle's fields at its phases (relative to their mean) and the spectrum
    at the phase of larger power, over the frames `which` ("all", or "last" for a run still
    growing, whose last frame is its largest)."""
    cycle, phase, fields, (lx, ly) = frames
    last, views = last_cycle_views(cycle, phase, fields)
    power = mode_power(fields)
    if which == "last":
        keep = cycle == last
        cycle, phase, power = cycle[keep], phase[keep], power[keep]
    best = max(np.unique(phase), key=lambda p: power[phase == p].sum(axis=1).mean())
    mean, error = spectrum_at(phase, power, best)
    return dict(box=[lx, ly], cycle=last, spectrum_phase=float(best), frames=int(
        (phase == best).sum()), power=rounded(mean), power_error=rounded(error),
        fields={f"{p:g}": rounded(f / f.mean() - 1.0) for p, f in views.items()})


def rounded(values):
    """Nested lists of `values` to DIGITS significant digits, None where not finite."""
    keep = np.vectorize(lambda v: float(f"{v:.{DIGITS}g}") if np.isfinite(v) else None,
                        otypes=[object])
    return keep(np.asarray(values, float)).tolist()
