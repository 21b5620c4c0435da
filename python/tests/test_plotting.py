"""The plotting helpers on synthetic runs: every axis labelled with units in brackets, a
legend naming what is drawn (the plate included), a colorbar on the map, and the data drawn
are the run's."""
import os
import re

import matplotlib
import numpy as np
import pytest

import granular_shaker as gs
import synthetic_files as synthetic
from granular_shaker import plotting

matplotlib.use("Agg")
UNIT = re.compile(r"\S.* \[[^\]]+\]$")


@pytest.fixture
def runs(work_dir):
    md, continuum = os.path.join(work_dir, "md.h5"), os.path.join(work_dir, "continuum.h5")
    synthetic.write_md_run(md)
    synthetic.write_continuum_run(continuum)
    return md, continuum


def data_axes(figure):
    """The axes that draw data (not colorbars)."""
    return [ax for ax in figure.axes if not hasattr(ax, "_colorbar")]


def check_labels_and_legend(figure, legend_must_name=("plate",)):
    axes = data_axes(figure)
    assert axes
    for ax in axes:
        assert UNIT.match(ax.get_xlabel()), ax.get_xlabel()
        assert UNIT.match(ax.get_ylabel()), ax.get_ylabel()
        legend = ax.get_legend()
        assert legend is not None
        entries = [t.get_text() for t in legend.get_texts()]
        for word in legend_must_name:
            assert any(word in entry for entry in entries), (word, entries)
    figure.savefig(os.devnull, format="png")  # draws without error
    return axes


@pytest.mark.parametrize("frame", ["lab", "plate"])
def test_profiles_with_md_bands(runs, frame):
    run = gs.read_run(runs[0], frame=frame)
    figure = plotting.plot_profiles(run, ("n", "T", "uz"), phases=(0.0, 0.5))
    axes = check_labels_and_legend(figure, ("plate", "MD, f t = 0.5", "standard error"))
    assert [ax.get_ylabel() for ax in axes] == [
        "number density n [1/sigma^3]", "granular temperature T [g sigma]",
        "vertical velocity u_z [sqrt(g sigma)]" if frame == "lab" else
        "vertical velocity u_z - v_p [sqrt(g sigma)]"]
    assert axes[0].get_xlabel() == ("height z [sigma]" if frame == "lab"
                                    else "height above the plate z - z_p [sigma]")
    lines = [line for line in axes[1].get_lines() if line.get_label().startswith("MD")]
    np.testing.assert_array_equal(lines[1].get_ydata(), run.profiles["T"][2])
    np.testing.assert_array_equal(lines[1].get_xdata(), run.profiles["z"][2])
    plates = [line.get_xdata()[0] for line in axes[0].get_lines() if line.get_linestyle() == ":"]
    np.testing.assert_allclose(plates, run.plate_height()[[0, 2]], rtol=1e-15)
    assert len(axes[0].collections) == 2  # one standard-error band per phase


def test_space_time_map_has_a_colorbar(runs):
    run = gs.read_run(runs[1])
    figure = plotting.plot_space_time(run, "T")
    check_labels_and_legend(figure)
    colorbars = [ax for ax in figure.axes if hasattr(ax, "_colorbar")]
    assert len(colorbars) == 1
    assert colorbars[0].get_ylabel() == "granular temperature T [g sigma]"
    (ax,) = data_axes(figure)
    assert ax.get_xlabel() == "phase f t [cycles]"
    mesh = ax.collections[0]
    np.testing.assert_array_equal(mesh.get_array().ravel(), run.profiles["T"].ravel())
    # The cells of each phase start at that phase's plate.
    corners = mesh.get_coordinates()
    assert corners.shape == (synthetic.PHASES + 1, synthetic.BINS + 1, 2)
    assert corners[1:-1, 0, 1] == pytest.approx(
        (run.profiles["plate_z"][1:] + run.profiles["plate_z"][:-1]) / 2, rel=1e-14)


def test_center_of_mass_and_shock_against_phase():
    analysis = gs.read_analysis_json(synthetic.analysis_json())
    figure = plotting.plot_center_of_mass_and_shock([analysis])
    (ax,) = check_labels_and_legend(figure, ("plate", "centre of mass (MD)",
                                             "shock location (MD)"))
    assert ax.get_xlabel() == "phase f t [cycles]" and ax.get_ylabel() == "height z [sigma]"
    shock = next(line for line in ax.get_lines() if line.get_label() == "shock location (MD)")
    np.testing.assert_array_equal(shock.get_ydata(),
                                  analysis.per_phase["shock_location"].value)


def test_md_against_continuum(runs):
    md, continuum = gs.read_run(runs[0]), gs.read_run(runs[1])
    figure = plotting.plot_md_against_continuum(md, continuum, "n", phases=(0.25, 0.75))
    axes = check_labels_and_legend(figure, ("plate", "MD", "continuum"))
    assert [ax.get_title() for ax in axes] == ["f t = 0.25", "f t = 0.75"]
    continuum_line = next(line for line in axes[1].get_lines() if line.get_label() == "continuum")
    np.testing.assert_array_equal(continuum_line.get_ydata(), continuum.profiles["n"][3])
    with pytest.raises(ValueError, match="the MD run is in the lab frame, the continuum run in "
                                         "the plate frame"):
        plotting.plot_md_against_continuum(md, gs.read_run(runs[1], frame="plate"))


def every_figure(runs):
    """Every plot_* helper of granular_shaker.plotting, drawn once."""
    md, continuum = gs.read_run(runs[0]), gs.read_run(runs[1])
    return {
        "plot_profiles": plotting.plot_profiles(md, ("n", "T", "uz"), phases=(0.0, 0.5)),
        "plot_center_of_mass_and_shock": plotting.plot_center_of_mass_and_shock(
            [gs.read_analysis_json(synthetic.analysis_json())]),
        "plot_space_time": plotting.plot_space_time(continuum, "T"),
        "plot_md_against_continuum": plotting.plot_md_against_continuum(md, continuum, "n"),
    }


def test_every_helper_meets_the_reports_figure_rules(runs):
    """The rules every report figure meets (granular_shaker.reports.figure_rules: units in
    brackets, legends, colorbars, MD errors, nothing overlapping), for every public helper."""
    from granular_shaker.reports.figure_rules import figure_problems
    figures = every_figure(runs)
    helpers = {name for name in dir(plotting) if name.startswith("plot_")}
    assert set(figures) == helpers
    for name, figure in figures.items():
        assert figure_problems(figure) == [], name
