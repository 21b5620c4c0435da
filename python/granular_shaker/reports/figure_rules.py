"""What makes a report's figure fit to publish, as a check: figure_problems(fig) lists what
breaks these rules (empty when the figure is fine).

- Every axes that draws data labels both axes, each label with its units in brackets,
  `height z [sigma]`, `f t [1]` (docs/units.md). An axis shared with a labelled one (a row of
  panels sharing y, a twin's x) may go unlabelled; an axis of named categories (text tick
  labels) needs a label but no units.
- An axes drawing more than one thing names every one of them in a legend, its own or one of
  the figure's; a colour-mapped image, mesh, filled contour or scatter is named by a colorbar
  instead. A legend inside the axes hides none of its data points (markers and the vertices
  of lines).
- MD data (a legend label starting with "MD") is drawn with its standard errors: as error
  bars, or as a band whose label says "standard error".
- Every colour-mapped artist has a colorbar in the figure (its own, or one of the same colour
  map and limits), whose label gives the units.
- No title or axis label overlaps the title, axis label or tick labels of another axes (or
  the figure's title or legend), and none (nor a figure legend) is cut off at the figure's
  edge; measured on the text as drawn (Agg).

The report tests (python/tests/harness/reports/test_figures.py) hold every figure function of
the report generators to these rules.
"""
import math
import re

import matplotlib.cm
import matplotlib.container
import matplotlib.lines
import matplotlib.ticker

UNITS = re.compile(r"\[[^\[\]]+\]")
# Text boxes may touch; they overlap when they share more than this in both directions.
OVERLAP_PIXELS = 0.5


def figure_problems(fig):
    if not hasattr(fig.canvas, "get_renderer"):  # a Figure made without pyplot has no backend
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    colorbars = colorbars_of(fig)
    problems = []
    for number, ax in enumerate(fig.axes):
        if ax in {cb.ax for cb in colorbars} or not ax.get_visible():
            continue
        if not drawn_artists(ax):
            continue
        name = f"axes {number} ({ax.get_title() or 'untitled'})"
        problems += [f"{name}: {p}" for p in label_problems(ax) + legend_problems(ax, fig)
                     + md_error_problems(ax) + colorbar_problems(ax, colorbars)]
    return problems + overlap_problems(fig)


# ---- axis labels ------------------------------------------------------------------------------

def label_problems(ax):
    if not ax.axison:
        return []
    problems = []
    for which, axis, shared in (("x", ax.xaxis, ax.get_shared_x_axes()),
                                ("y", ax.yaxis, ax.get_shared_y_axes())):
        if not axis.get_visible():
            continue
        text = axis.get_label_text().strip()
        if not text and any(axis_label_is_good(other, which) for other in
                            shared.get_siblings(ax) if other is not ax):
            continue
        if not text:
            problems.append(f"no {which} label")
        elif not UNITS.search(text) and not is_categorical(axis):
            problems.append(f"{which} label '{text}' gives no units in brackets")
    return problems


def axis_label_is_good(ax, which):
    axis = ax.xaxis if which == "x" else ax.yaxis
    text = axis.get_label_text()
    return bool(text.strip()) and (bool(UNITS.search(text)) or is_categorical(axis))


def is_categorical(axis):
    """An axis whose ticks are named by text (variants, commits), not by their values: labels
    set by hand (set_ticklabels) of which one at least does not read as its tick's value."""
    if not isinstance(axis.get_major_formatter(), (matplotlib.ticker.FixedFormatter,
                                                   matplotlib.ticker.FuncFormatter)):
        return False
    for value, label in zip(axis.get_majorticklocs(), axis.get_ticklabels()):
        try:
            shown = float(label.get_text().replace("\u2212", "-"))
        except ValueError:
            return True
        if not math.isclose(shown, value, rel_tol=1e-3, abs_tol=1e-12):
            return True
    return False


# ---- legends and colorbars ----------------------------------------------------------------------

def colorbars_of(fig):
    return list({id(m.colorbar): m.colorbar for ax in fig.axes for m in mapped_artists(ax)
                 if m.colorbar is not None}.values())


def mapped_artists(ax):
    """The artists whose colour carries a value: images, meshes, filled contours and
    scatters coloured by a value."""
    return [a for a in list(ax.images) + list(ax.collections)
            if isinstance(a, matplotlib.cm.ScalarMappable) and a.get_array() is not None]


def drawn_artists(ax):
    """What the axes draws, an errorbar's line, bars and caps counted once (its container)."""
    in_containers = {id(child) for c in ax.containers for child in c.get_children()}
    artists = [a for a in list(ax.lines) + list(ax.collections) + list(ax.patches)
               + list(ax.images) if a.get_visible() and id(a) not in in_containers]
    return artists + list(ax.containers)


def legend_problems(ax, fig):
    mapped = {id(a) for a in mapped_artists(ax)}
    named = [a for a in drawn_artists(ax) if id(a) not in mapped]
    if len(named) <= 1:
        return []
    problems = []
    unlabelled = [a for a in named if a.get_label().startswith("_")]
    if unlabelled:
        kinds = sorted({type(a).__name__ for a in unlabelled})
        problems.append(f"{len(unlabelled)} drawn artists without a label for the legend "
                        f"({', '.join(kinds)})")
    shown = set()
    for legend in ([ax.get_legend()] if ax.get_legend() else []) + list(fig.legends):
        shown |= {t.get_text() for t in legend.get_texts()}
    missing = sorted({a.get_label() for a in named if not a.get_label().startswith("_")} - shown)
    if missing:
        problems.append("no legend names " + ", ".join(f"'{m}'" for m in missing))
    hidden = covered_points(ax)
    if hidden:
        problems.append(f"its legend hides {hidden} data points")
    return problems


def covered_points(ax):
    """How many data points (markers and line vertices, in view) the axes' own legend
    hides."""
    legend = ax.get_legend()
    if legend is None:
        return 0
    box = legend.get_window_extent(ax.figure.canvas.get_renderer())
    view = ax.bbox
    hidden = 0
    for line in ax.lines:
        if not line.get_visible() or len(line.get_xydata()) == 0:
            continue
        points = ax.transData.transform(line.get_xydata())
        inside = ((points[:, 0] > view.x0) & (points[:, 0] < view.x1)
                  & (points[:, 1] > view.y0) & (points[:, 1] < view.y1))
        hidden += int(sum(box.contains(x, y) for x, y in points[inside]))
    return hidden


def md_error_problems(ax):
    md = [a for a in drawn_artists(ax) if a.get_label().startswith("MD")]
    bars = [a for a in md if isinstance(a, matplotlib.container.ErrorbarContainer)]
    problems = [f"MD series '{a.get_label()}' drawn without error bars" for a in bars
                if not (a.has_xerr or a.has_yerr)]
    bands = [a for a in md if not isinstance(a, matplotlib.lines.Line2D)
             and "standard error" in a.get_label()]
    if md and not bars and not bands:
        problems.append("MD data (" + ", ".join(f"'{a.get_label()}'" for a in md)
                        + ") without its standard errors")
    return problems


def colorbar_problems(ax, colorbars):
    problems = []
    for artist in mapped_artists(ax):
        bar = artist.colorbar or next(
            (cb for cb in colorbars if cb.mappable.get_cmap().name == artist.get_cmap().name
             and cb.mappable.get_clim() == artist.get_clim()), None)
        if bar is None:
            problems.append(f"colour-mapped {type(artist).__name__} without a colorbar")
            continue
        label = bar.ax.get_ylabel() if bar.orientation == "vertical" else bar.ax.get_xlabel()
        if not UNITS.search(label):
            problems.append(f"colorbar label '{label}' gives no units in brackets")
    return problems


# ---- overlapping and cut-off text ---------------------------------------------------------------

def own_texts(ax):
    """Title(s) and axis labels of an axes, as drawn."""
    texts = [ax.title, getattr(ax, "_left_title", None), getattr(ax, "_right_title", None),
             ax.xaxis.label, ax.yaxis.label]
    return [t for t in texts if t is not None and shown(t)]


def tick_texts(ax):
    """The tick labels drawn: those of ticks inside the view limits."""
    if not ax.get_visible():
        return []
    texts = []
    for axis in (ax.xaxis, ax.yaxis):
        low, high = sorted(axis.get_view_interval())
        slack = 1e-9 * (abs(low) + abs(high))
        for tick in axis.get_major_ticks() + axis.get_minor_ticks():
            if low - slack <= tick.get_loc() <= high + slack:
                texts += [t for t in (tick.label1, tick.label2) if shown(t)]
    return texts


def shown(text):
    return text.get_visible() and bool(text.get_text().strip()) and \
        (text.axes is None or text.axes.get_visible())


def overlap_problems(fig):
    """Texts (and figure legends) of different owners that overlap, or that the figure's edge
    cuts off; an owner is an axes, or the figure for its title and legends."""
    renderer = fig.canvas.get_renderer()
    figure_texts = [t for t in dict.fromkeys([getattr(fig, "_suptitle", None)] + fig.texts)
                    if t is not None and shown(t)]  # the title is one of fig.texts too
    owners = [(None, [(f"'{t.get_text()}'", t.get_window_extent(renderer))
                      for t in figure_texts]
               + [("the figure's legend", legend.get_window_extent(renderer))
                  for legend in fig.legends])]
    owners += [(ax, [(f"'{t.get_text()}'", t.get_window_extent(renderer))
                     for t in own_texts(ax)]) for ax in fig.axes]
    ticks = {ax: [t.get_window_extent(renderer) for t in tick_texts(ax)] for ax in fig.axes}
    edge = fig.bbox
    problems = [f"{name} is cut off at the figure's edge" for _, boxes in owners
                for name, box in boxes if box.x0 < edge.x0 - 1 or box.y0 < edge.y0 - 1
                or box.x1 > edge.x1 + 1 or box.y1 > edge.y1 + 1]
    figure_boxes = owners[0][1]
    problems += [f"{name} overlaps {other}" for i, (name, box) in enumerate(figure_boxes)
                 for other, other_box in figure_boxes[i + 1:] if overlap(box, other_box)]
    for i, (owner, boxes) in enumerate(owners):
        for _, other_boxes in owners[i + 1:]:
            problems += [f"{name} overlaps {other}" for name, box in boxes
                         for other, other_box in other_boxes if overlap(box, other_box)]
        problems += [f"{name} overlaps the tick labels of another axes"
                     for other_owner in fig.axes if other_owner is not owner
                     for name, box in boxes
                     if any(overlap(box, tick) for tick in ticks[other_owner])]
    return problems


def overlap(a, b):
    return min(a.x1, b.x1) - max(a.x0, b.x0) > OVERLAP_PIXELS and \
        min(a.y1, b.y1) - max(a.y0, b.y0) > OVERLAP_PIXELS
