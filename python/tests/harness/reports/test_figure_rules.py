"""ctest reports.figure_rules: the checker of granular_shaker.reports.figure_rules on figures
made to break one rule each, and on a figure that keeps them all (shared and twin axes, a
categorical axis, MD error bars, a colorbar shared by two meshes, a figure legend).
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from granular_shaker.reports.figure_rules import figure_problems  # noqa: E402

X = np.linspace(0.0, 1.0, 5)


def labelled(ax, x="phase f t [1]", y="height z [sigma]"):
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    return ax


def good_figure():
    fig, axes = plt.subplots(2, 2, figsize=(9, 7), sharey="row")
    a, b = axes[0]
    labelled(a)
    a.errorbar(X, X, yerr=0.1 * X, fmt="o", label="MD (± standard error)")
    a.plot(X, X ** 2, label="continuum")
    a.axhline(0.0, color="k", label="plate")
    a.legend()
    b.set_xlabel("phase f t [1]")  # its y axis is a's
    b.plot(X, X)
    twin = b.twinx()
    twin.plot(X, 3 * X, "r")
    twin.set_ylabel("temperature T [g sigma]")
    c, d = axes[1]
    grid = np.outer(X, X)
    for ax in (c, d):
        mesh = ax.pcolormesh(X, X, grid, vmin=0, vmax=1, cmap="viridis", shading="nearest")
        labelled(ax)
    d.sharey(c)
    d.set_ylabel("")  # shared with c's
    c.set_title("variants")
    fig.tight_layout()
    fig.colorbar(mesh, ax=[c, d]).set_label("volume fraction nu [1]")
    return fig


def categorical_figure():
    fig, ax = plt.subplots(figsize=(5, 3))
    ax.plot([1, 2, 3], [0, 1, 2], "o")
    ax.set_yticks([0, 1, 2])
    ax.set_yticklabels(["base", "wide", "narrow"])
    labelled(ax, y="variant")
    fig.tight_layout()
    return fig


def no_x_label():
    fig, ax = plt.subplots()
    ax.plot(X, X)
    ax.set_ylabel("height z [sigma]")
    return fig


def no_units():
    fig, ax = plt.subplots()
    ax.plot(X, X)
    labelled(ax, y="height")
    return fig


def two_lines_no_legend():
    fig, ax = plt.subplots()
    ax.plot(X, X, label="one")
    ax.plot(X, X ** 2, label="other")
    labelled(ax)
    return fig


def unlabelled_plate():
    fig, ax = plt.subplots()
    ax.plot(X, X, label="continuum")
    ax.axhline(0.0, color="k")
    ax.legend()
    labelled(ax)
    return fig


def legend_on_the_data():
    fig, ax = plt.subplots()
    ax.plot(X, X, "o", label="rising")
    ax.plot(X, 0.5 * X, "s", label="slower")
    ax.legend(loc="upper right", fontsize=20)
    labelled(ax)
    return fig


def md_without_errors():
    fig, ax = plt.subplots()
    ax.plot(X, X, "o", label="MD")
    labelled(ax)
    return fig


def mesh_without_colorbar():
    fig, ax = plt.subplots()
    ax.pcolormesh(X, X, np.outer(X, X), shading="nearest")
    labelled(ax)
    return fig


def colorbar_without_units():
    fig, ax = plt.subplots()
    fig.colorbar(ax.pcolormesh(X, X, np.outer(X, X), shading="nearest")).set_label("nu")
    labelled(ax)
    return fig


def overlapping_titles():
    """The upper panel's x label on the lower panel's title (no layout)."""
    fig, (a, b) = plt.subplots(2, 1, figsize=(6, 5))
    for ax in (a, b):
        ax.plot(X, X)
        labelled(ax)
    b.set_title("the lower panel")
    return fig


def legend_on_the_title():
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(X, X, label="data")
    labelled(ax)
    fig.suptitle("A figure title")
    fig.tight_layout()
    fig.legend(loc="upper center")
    return fig


def cut_off_label():
    fig, ax = plt.subplots(figsize=(3, 3))
    ax.plot(X, X)
    labelled(ax, x="a label far too long for a narrow figure, running off its edge [1]")
    fig.tight_layout()
    return fig


def test_a_figure_that_keeps_the_rules_passes():
    for make in (good_figure, categorical_figure):
        fig = make()
        assert figure_problems(fig) == [], make.__name__
        plt.close(fig)


@pytest.mark.parametrize("make, problem", [
    (no_x_label, "no x label"),
    (no_units, "y label 'height' gives no units"),
    (two_lines_no_legend, "no legend names 'one', 'other'"),
    (unlabelled_plate, "1 drawn artists without a label"),
    (legend_on_the_data, "its legend hides"),
    (md_without_errors, "MD data ('MD') without its standard errors"),
    (mesh_without_colorbar, "colour-mapped QuadMesh without a colorbar"),
    (colorbar_without_units, "colorbar label 'nu' gives no units"),
    (overlapping_titles, "overlaps"),
    (legend_on_the_title, "'A figure title' overlaps the figure's legend"),
    (cut_off_label, "is cut off at the figure's edge"),
])
def test_each_broken_rule_is_found(make, problem):
    fig = make()
    problems = figure_problems(fig)
    plt.close(fig)
    print(f"{make.__name__}: {problems}")
    assert problems and all(problem in p for p in problems), \
        f"{make.__name__}: expected only '{problem}', found {problems}"
