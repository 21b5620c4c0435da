"""The pattern report's top views and spectra (granular_shaker.patterns.views) on synthetic
particle and field files of known stripes: the column mass, the power of each mode along x,
the last complete cycle's views and the spectrum's error over frames.

    python3 -m pytest python/tests/test_pattern_views.py
"""
import numpy as np
import pytest

import synthetic_files as synthetic
from granular_shaker.patterns.views import (column_mass_frames, last_cycle_views, mode_power,
                                            phase_spectra, run_view)

LX, LY, PARTICLES, MODE = 128.0, 8.0, 12800, 6
AMPLITUDE = {0.0: 0.4, 0.5: 0.1}   # relative amplitude of the stripes at each phase
FRAMES = [(c, p) for c in (10, 11, 12) for p in (0.0, 0.5)]


def stripe_positions(amplitude, sign):
    """Particles whose density along x is 1 + sign * amplitude * cos(2 pi MODE x / LX), placed
    at the quantiles of that density (no sampling noise beyond the binning), uniform in y."""
    fine = np.linspace(0.0, LX, 200001)
    density = 1.0 + sign * amplitude * np.cos(2 * np.pi * MODE * fine / LX)
    cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1])
                                                  * np.diff(fine))])
    quantiles = (np.arange(PARTICLES) + 0.5) / PARTICLES * cumulative[-1]
    x = np.interp(quantiles, cumulative, fine)
    y = (np.arange(PARTICLES) * 0.618034 % 1.0) * LY
    return np.column_stack([x, y, np.full(PARTICLES, 1.0)])


def write_md_particles(path, frames=FRAMES):
    # The subharmonic stripes: the pattern inverts from one cycle to the next.
    position = np.stack([stripe_positions(AMPLITUDE[p], (-1.0) ** c) for c, p in frames])
    steps = np.arange(len(frames), dtype=np.int64)
    time = np.array([c + p for c, p in frames]) / 0.18
    observables = {"plate_position": (np.zeros(len(frames)), "sigma"),
                   "plate_velocity": (np.zeros(len(frames)), "sqrt(g sigma)"),
                   "phase": (np.array([p for _, p in frames]), "1"),
                   "cycle": (np.array([float(c) for c, _ in frames]), "1")}
    synthetic.write_particle_file(path, steps, time, position, np.zeros_like(position),
                                  [LX, LY, 100.0], steps, time, observables)


def test_md_column_mass_and_its_stripe_mode(tmp_path):
    write_md_particles(tmp_path / "run.particles.h5")
    cycle, phase, fields, box = column_mass_frames(tmp_path / "run.h5", cell=2.0)
    assert box == (LX, LY) and fields.shape == (6, 64, 4)
    assert list(cycle) == [10, 10, 11, 11, 12, 12] and list(phase) == [0.0, 0.5] * 3
    assert fields.mean(axis=(1, 2)) == pytest.approx(PARTICLES / (LX * LY), rel=1e-12)
    power = mode_power(fields)
    assert np.argmax(power, axis=1).tolist() == [MODE - 1] * 6
    # A cosine of relative amplitude a has |c_m| / c_0 = a / 2; binning on 2-sigma cells
    # (21.3 / 2 cells a wavelength) lowers it by sinc(pi m dx / Lx), about 1.5 %.
    binning = np.sinc(MODE * 2.0 / LX)
    for row, p in enumerate(phase):
        assert power[row, MODE - 1] == pytest.approx((AMPLITUDE[p] / 2 * binning) ** 2,
                                                     rel=0.01)
    # Every other mode holds only the rounding of each cell to whole particles (200 a cell).
    assert np.delete(power, MODE - 1, axis=1).max() < 1e-3 * power[:, MODE - 1].min()


def test_the_view_is_the_last_complete_cycle_and_the_spectrum_of_the_stronger_phase(tmp_path):
    frames = FRAMES + [(13, 0.0)]   # the last cycle holds one phase only
    write_md_particles(tmp_path / "run.particles.h5", frames)
    cycle, phase, fields, _ = column_mass_frames(tmp_path / "run.h5")
    last, views = last_cycle_views(cycle, phase, fields)
    assert last == 12.0 and sorted(views) == [0.0, 0.5]
    view = run_view(column_mass_frames(tmp_path / "run.h5"))
    assert view["cycle"] == 12.0 and view["spectrum_phase"] == 0.0 and view["frames"] == 4
    assert view["box"] == [LX, LY]
    relative = np.array(view["fields"]["0"])
    assert relative.shape == (64, 4) and abs(relative.mean()) < 1e-3
    # Cycle 12 is even: its stripes have a crest at x = 0.
    assert relative[0].mean() > 0.3 and view["power"][MODE - 1] > 0.035
    # Identical frames at a phase: the spectrum's standard error is zero there.
    assert view["power_error"][MODE - 1] == pytest.approx(0.0, abs=1e-12)


def test_the_spectra_at_every_phase_hold_each_stripes_amplitude(tmp_path):
    write_md_particles(tmp_path / "run.particles.h5")
    spectra = phase_spectra(column_mass_frames(tmp_path / "run.h5"))
    assert spectra["box_length"] == LX and sorted(spectra["power"]) == ["0", "0.5"]
    for phase, amplitude in AMPLITUDE.items():
        # |c_m| / c_0 of 1 + a cos is a / 2, less the binning's attenuation of mode 6 on
        # 2-sigma cells (sinc(pi 6 * 2 / 128) = 0.986); the whole particles in each cell of
        # about 200 round it by a few 1e-4.
        power = spectra["power"][f"{phase:g}"][MODE - 1]
        assert np.sqrt(power) == pytest.approx(0.986 * amplitude / 2, abs=5e-4)
        assert spectra["power_error"][f"{phase:g}"][MODE - 1] == pytest.approx(0.0, abs=1e-12)


def test_a_continuum_view_is_its_last_frame(tmp_path):
    frames = [(c, p) for c in range(10) for p in (0.0, 0.5)]
    synthetic.write_pattern_fields(tmp_path / "run.fields.h5", frames)
    cycle, phase, fields, box = column_mass_frames(tmp_path / "run.h5")
    assert box == (128.0, 8.0) and fields.shape == (20, 64, 4)
    view = run_view((cycle, phase, fields, box), which="last")
    assert view["cycle"] == 9.0 and view["frames"] == 1
    growing = (0.5e-4 * np.exp(0.9)) ** 2
    assert view["power"][MODE - 1] == pytest.approx(growing, rel=1e-3)
    assert view["power_error"][MODE - 1] is None   # one frame: no error
    assert mode_power(fields[:, :20, :]).shape == (20, 9)   # below the Nyquist mode 10
    with pytest.raises(ValueError, match="cannot hold"):
        mode_power(fields[:, :3, :])
