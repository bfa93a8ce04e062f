"""Figures of the convergence report, each a function of plain arrays that
returns a matplotlib Figure (Agg backend; no display needed):

* error_against_h: error norm against cell size h on log axes, one curve per
  refinement series, its least-squares line C h^p (reports/orders.py) dashed,
  and reference slopes 1 and 2;
* work_precision: error at the end time against wall time, one curve per
  method, the Pareto front (no other case is both faster and more accurate)
  marked;
* stability_map: how far every case got (the style of table 3.2 of
  000_1dbcb8acb6dddab9.txt): columns = cells, rows = method settings, colour =
  fraction of the end time reached, text = time reached and failure reason;
* profiles: simulated against exact along a probe line or over time, with
  the difference below;
* error_spectra: one-sided amplitude of mode m of the error around the ring's
  material circle (/probes/circle/error_spectrum); the exact motion is
  axisymmetric, so every mode m > 0 is lost axisymmetry;
* pressure_profiles: simulated values as markers, one series per refinement
  level, against an exact curve drawn as a line (the Hertz contact pressure);
* histories: one line per case of a scalar against another recorded after
  every step (the Hertz load against approach);
* log_curves: panels of curves on a logarithmic error axis, a marker at every
  value (the ring's L1 over time and its marker refinement, ring_figures.py);
* particle_maps: the particles at chosen output times coloured by a field and,
  below, by their displacement error (the maps of the Sandia report);
(the run-health figure is health_plot.py's).
"""
import math
import textwrap
from dataclasses import dataclass, field

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend is chosen first)
import numpy as np  # noqa: E402

COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*"]
NO_RESULTS_COLOUR = "#d9d9d9"


@dataclass(frozen=True)
class Style:
    colour: str = COLOURS[0]
    marker: str = MARKERS[0]


@dataclass
class Curve:
    label: str
    x: list
    y: list
    style: Style = field(default_factory=Style)
    fit: object = None            # orders.OrderFit drawn as C x^p over the curve's x range


@dataclass
class StabilityCell:
    fraction: float               # time reached / end time; NaN when there are no results
    text: str
    stopped: bool = False         # the run did not reach its end time (drawn hatched)


@dataclass
class StabilityPanel:
    title: str
    columns: list                 # values of the refine key
    rows: list                    # labels of the method settings
    cells: dict                   # (row label, column value) -> StabilityCell


@dataclass
class Snapshot:
    label: str                    # e.g. "t = 0.5 s"; "" when there is one
    simulated: np.ndarray
    exact: np.ndarray


@dataclass
class ProfilePanel:
    title: str
    x: np.ndarray
    snapshots: list               # Snapshot, drawn against x


@dataclass
class LinePanel:
    title: str
    curves: list                  # Curve, one per case
    exact: Curve = None           # drawn as a black line under the curves
    marks: list = field(default_factory=list)   # (x, label): dotted vertical lines


def _finite_positive(x, y):
    pairs = [(a, b) for a, b in zip(x, y) if a > 0 and b > 0 and math.isfinite(a) and math.isfinite(b)]
    return [a for a, _ in pairs], [b for _, b in pairs]


def error_against_h(curves, title, y_label, x_label="cell size h [m]"):
    figure, axes = plt.subplots(figsize=(10.5, 5.0), constrained_layout=True)
    all_h, all_e = [], []
    fitted = with_interval = False
    for curve in curves:
        h, e = _finite_positive(curve.x, curve.y)
        if not h:
            continue
        all_h += h
        all_e += e
        label = curve.label
        if curve.fit is not None and math.isfinite(curve.fit.order):
            fitted = True
            label += f": p = {curve.fit.order:.2f}"
            if math.isfinite(curve.fit.ci_low):
                with_interval = True
                label += f" [{curve.fit.ci_low:.2f}, {curve.fit.ci_high:.2f}]"
            line_h = np.geomspace(min(h), max(h), 20)
            axes.plot(line_h, curve.fit.error_constant * line_h ** curve.fit.order, "--",
                      color=curve.style.colour, linewidth=1.0)
        axes.plot(h, e, marker=curve.style.marker, color=curve.style.colour, linestyle="-", linewidth=1.2,
                  markersize=6, label=label)
    if all_h:
        _reference_slopes(axes, min(all_h), max(all_h), min(all_e))
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel(x_label)
    axes.set_ylabel(y_label)
    axes.set_title(title)
    axes.grid(True, which="both", alpha=0.3)
    if all_h:
        # The title claims what the labels show: an order only where one was
        # fitted, an interval only where one exists (two levels have none).
        title = ("series: least-squares order p" + (" [95% CI]" if with_interval else "")) if fitted else "series"
        axes.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                    title=title, title_fontsize=8)
    else:
        _no_data(axes)
    return figure


def _reference_slopes(axes, h_min, h_max, e_min):
    """Lines E proportional to h and h^2 that end at the lowest error at the smallest h."""
    line_h = np.geomspace(h_min, h_max, 20)
    anchor = 0.5 * e_min
    for order, style in ((1, ":"), (2, "-.")):
        axes.plot(line_h, anchor * (line_h / h_min) ** order, style, color="grey", linewidth=1.0)
        axes.annotate(f"slope {order}", (line_h[-1], anchor * (h_max / h_min) ** order), fontsize=8,
                      color="grey", xytext=(3, 0), textcoords="offset points", va="center")


def _no_data(axes):
    axes.text(0.5, 0.5, "no usable level", transform=axes.transAxes, ha="center", va="center", color="grey")


def pareto_front(points):
    """The points (x, y) that no other point beats in both x and y (lower is better), by x."""
    front = []
    for x, y in sorted(points):
        if not front or y < front[-1][1]:
            front.append((x, y))
    return front


def _panel_grid(count, width=4.6, height=3.8, columns_max=3):
    columns = min(count, columns_max)
    rows = math.ceil(count / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(max(width * columns, 8.0), height * rows + 0.6),
                                squeeze=False, constrained_layout=True)
    for extra in axes.flat[count:]:
        extra.set_visible(False)
    return figure, list(axes.flat[:count])


def work_precision(panels, title, y_label):
    """panels: list of (panel title, curves with x = wall time [s], y = error)."""
    figure, axes_list = _panel_grid(len(panels), width=5.2, height=4.2)
    for axes, (panel_title, curves) in zip(axes_list, panels):
        points = []
        for curve in curves:
            wall, error = _finite_positive(curve.x, curve.y)
            if wall:
                axes.plot(wall, error, marker=curve.style.marker, color=curve.style.colour, label=curve.label)
                points += list(zip(wall, error))
        front = pareto_front(points)
        if front:
            fx, fy = zip(*front)
            axes.step(fx, fy, where="post", color="black", linewidth=0.8, alpha=0.6)
            axes.plot(fx, fy, "o", markersize=12, markerfacecolor="none", markeredgecolor="black",
                      label="Pareto front")
            axes.set_xscale("log")
            axes.set_yscale("log")
            axes.legend(fontsize=8)
        else:
            _no_data(axes)
        label_panel(axes, "wall time of the time loop [s]", y_label, panel_title)
    suptitle(figure, title)
    return figure


def stability_map(panels, title, column_label):
    colour_map = plt.get_cmap("RdYlGn")
    width = max(len(p.columns) for p in panels) * 1.05 + 1.6
    height = max(len(p.rows) for p in panels) * 0.62 + 1.0
    figure, axes_list = _panel_grid(len(panels), width=width, height=height, columns_max=2)
    for axes, panel in zip(axes_list, panels):
        for i, row in enumerate(panel.rows):
            for j, column in enumerate(panel.columns):
                cell = panel.cells.get((row, column))
                if cell is None:
                    continue
                colour = NO_RESULTS_COLOUR if not math.isfinite(cell.fraction) else colour_map(cell.fraction)
                axes.add_patch(plt.Rectangle((j, i), 1, 1, facecolor=colour, edgecolor="white", linewidth=2))
                if cell.stopped:
                    axes.add_patch(plt.Rectangle((j + 0.04, i + 0.06), 0.92, 0.88, fill=False, hatch="///",
                                                 edgecolor=(0, 0, 0, 0.18), linewidth=0))
                axes.text(j + 0.5, i + 0.5, cell.text, ha="center", va="center", fontsize=7)
        axes.set_xlim(0, len(panel.columns))
        axes.set_ylim(len(panel.rows), 0)
        axes.set_xticks([j + 0.5 for j in range(len(panel.columns))], [str(c) for c in panel.columns])
        axes.set_yticks([i + 0.5 for i in range(len(panel.rows))], panel.rows)
        axes.set_xlabel(column_label)
        axes.set_title(panel.title, fontsize=9)
        axes.tick_params(length=0, labelsize=8)
        for spine in axes.spines.values():
            spine.set_visible(False)
    scale = plt.cm.ScalarMappable(norm=matplotlib.colors.Normalize(0, 1), cmap=colour_map)
    # A tall map (many rows) keeps a colour bar of a readable length, not its height.
    figure.colorbar(scale, ax=axes_list, label="fraction of end time reached",
                    shrink=min(0.8, 5.0 / figure.get_figheight()), aspect=15)
    suptitle(figure, title)
    return figure


def profiles(panels, title, x_label, y_label, unit, markers=True):
    """Top row: simulated and exact, one colour per time of a panel's `snapshots`;
    bottom row: simulated - exact. markers=False draws the simulated values as a
    line (for histories of thousands of steps)."""
    columns = min(len(panels), 3)
    blocks = math.ceil(len(panels) / columns)
    figure, axes = plt.subplots(2 * blocks, columns, figsize=(4.6 * columns, 5.0 * blocks + 0.6), squeeze=False,
                                sharex="col", gridspec_kw={"height_ratios": [2, 1] * blocks},
                                constrained_layout=True)
    for index in range(blocks * columns):
        top, bottom = axes[2 * (index // columns), index % columns], axes[2 * (index // columns) + 1, index % columns]
        if index >= len(panels):
            top.set_visible(False)
            bottom.set_visible(False)
            continue
        panel = panels[index]
        for k, snapshot in enumerate(panel.snapshots):
            colour = COLOURS[k % len(COLOURS)]
            suffix = f" ({snapshot.label})" if snapshot.label else ""
            top.plot(panel.x, snapshot.exact, "-", color="black", linewidth=2.2 if k == 0 else 1.2,
                     alpha=0.45 if k == 0 else 1.0, label="exact" + suffix)
            top.plot(panel.x, snapshot.simulated, "o" if markers else "-", color=colour, markersize=3,
                     linewidth=1.0, label="simulated" + suffix)
            bottom.plot(panel.x, np.asarray(snapshot.simulated) - np.asarray(snapshot.exact), "-", color=colour,
                        linewidth=1.0)
        top.set_title(panel.title, fontsize=9)
        top.set_ylabel(y_label)
        top.legend(fontsize=7)
        top.grid(True, alpha=0.3)
        bottom.axhline(0.0, color="grey", linewidth=0.6)
        bottom.set_ylabel(f"simulated - exact [{unit}]")
        bottom.set_xlabel(x_label)
        bottom.grid(True, alpha=0.3)
        bottom.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    suptitle(figure, title)
    return figure


def error_spectra(panels, title, y_label, floors=None):
    """panels: list of (panel title, curves with x = mode m, y = amplitude), each
    mode a marker (the modes are discrete; no line joins them); floors: panel
    title -> the round-off floor of an amplitude, drawn dotted, the axis
    starting a decade below it so that the height goes to what is above it."""
    floors = floors or {}
    figure, axes_list = _panel_grid(len(panels), width=5.2, height=4.0)
    for axes, (panel_title, curves) in zip(axes_list, panels):
        drawn = False
        for curve in curves:
            m, amplitude = np.asarray(curve.x, float), np.asarray(curve.y, float)
            keep = amplitude > 0
            if keep.any():
                axes.plot(m[keep], amplitude[keep], marker=curve.style.marker, markersize=4, linestyle="none",
                          color=curve.style.colour, label=curve.label)
                drawn = True
        floor = floors.get(panel_title)
        if drawn and floor is not None and floor > 0:
            values = np.concatenate([np.asarray(c.y, float) for c in curves])
            above = values[np.isfinite(values) & (values > floor)]
            top = float(above.max()) if above.size else floor
            # the axis from a decade under the smallest mode above the floor: the
            # modes at round-off, below the floor, are not what the figure is for
            bottom = max(float(above.min()) / 10.0, floor / 3.0) if above.size else floor / 10.0
            if bottom <= floor:
                axes.axhline(floor, color="black", linestyle=":", linewidth=1.0, label="round-off floor")
            else:
                axes.text(0.99, 0.02, f"round-off floor {floor:.1e}, below the axis", transform=axes.transAxes,
                          ha="right", va="bottom", fontsize=7, color="grey")
            axes.set_ylim(bottom=bottom, top=max(top * 3.0, floor * 10.0))
        if drawn:
            axes.set_yscale("log")
            axes.legend(fontsize=8)
        else:
            _no_data(axes)
        label_panel(axes, "angular mode m around the circle", y_label, panel_title)
    suptitle(figure, title)
    return figure


def pressure_profiles(panels, title, x_label, y_label):
    """panels: LinePanel; each curve drawn as markers only, the exact curve as a line."""
    return _line_panels(panels, title, x_label, y_label, markers=True)


def histories(panels, title, x_label, y_label):
    """panels: LinePanel; each curve drawn as a line (histories have a point per step)."""
    return _line_panels(panels, title, x_label, y_label, markers=False)


def _line_panels(panels, title, x_label, y_label, markers):
    figure, axes_list = _panel_grid(len(panels), width=5.6, height=4.4)
    for axes, panel in zip(axes_list, panels):
        drawn = False
        if panel.exact is not None and len(panel.exact.x):
            axes.plot(panel.exact.x, panel.exact.y, "-", color="black", linewidth=1.6, alpha=0.75,
                      label=panel.exact.label, zorder=1)
            drawn = True
        for curve in panel.curves:
            if not len(curve.x):
                continue
            if markers:
                axes.plot(curve.x, curve.y, linestyle="none", marker=curve.style.marker, markersize=5,
                          color=curve.style.colour, label=curve.label, zorder=2)
            else:
                axes.plot(curve.x, curve.y, "-", color=curve.style.colour, linewidth=1.2, label=curve.label,
                          zorder=2)
            drawn = True
        for x, label in panel.marks:
            axes.axvline(x, color="grey", linestyle=":", linewidth=1.0)
            axes.annotate(label, (x, 1.0), xycoords=("data", "axes fraction"), xytext=(3, -3),
                          textcoords="offset points", ha="left", va="top", fontsize=8, color="grey")
        if drawn:
            axes.legend(fontsize=8)
        else:
            _no_data(axes)
        label_panel(axes, x_label, y_label, panel.title)
    suptitle(figure, title)
    return figure


def log_curves(panels, title, x_label, y_label, log_x=False):
    """panels: LinePanel; each curve drawn with a marker at every value and joined by
    a thin line, the error axis logarithmic (non-positive values are left out)."""
    figure, axes_list = _panel_grid(len(panels), width=5.6, height=4.4)
    for axes, panel in zip(axes_list, panels):
        drawn = False
        for curve in panel.curves:
            x, y = _finite_positive(curve.x, curve.y)
            if not x:
                continue
            axes.plot(x, y, "-", marker=curve.style.marker, markersize=4, linewidth=0.9, color=curve.style.colour,
                      label=curve.label)
            drawn = True
        if drawn:
            axes.set_yscale("log")
            if log_x:
                # Ticks at the values drawn (particles per direction 2, 4, 8), as plain numbers.
                axes.set_xscale("log")
                ticks = sorted({a for c in panel.curves for a in _finite_positive(c.x, c.y)[0]})
                axes.set_xticks(ticks, [f"{t:g}" for t in ticks])
                axes.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            plain_log_labels(axes)
            axes.legend(fontsize=7)
        else:
            _no_data(axes)
        label_panel(axes, x_label, y_label, panel.title)
    suptitle(figure, title)
    return figure


@dataclass
class ParticleMap:
    label: str                    # e.g. "t = 0.25 s"
    position: np.ndarray          # N x 2 [m]
    field: np.ndarray             # N, the top row's colour
    error: np.ndarray = None      # N, the bottom row's colour; None: no exact motion


def particle_maps(maps, title, field_label, error_label):
    """One column per map: the particles at their current positions coloured by the
    field (top) and by the error (bottom), one colour scale per row from 0 to the
    row's largest value, so an anomaly stands out as it does in the data."""
    rows = 2 if any(m.error is not None for m in maps) else 1
    figure, axes = plt.subplots(rows, len(maps), figsize=(max(3.6 * len(maps), 7.0), 3.4 * rows + 0.8),
                                squeeze=False, constrained_layout=True)
    for row, (values, label) in enumerate([("field", field_label), ("error", error_label)][:rows]):
        arrays = [getattr(m, values) for m in maps]
        top = max((float(np.nanmax(a)) for a in arrays if a is not None and a.size), default=1.0) or 1.0
        drawn = None
        for axes_k, m, a in zip(axes[row], maps, arrays):
            if a is None:
                _no_data(axes_k)
                continue
            # A marker about as large as a particle's share of its bounding box
            # (a panel is about 3 inches, 216 points, across), so the body reads filled.
            span = np.ptp(m.position, axis=0)
            points_per_m = 216.0 / max(float(span.max()), 1e-300)
            size = float(np.clip(0.7 * points_per_m ** 2 * span[0] * span[1] / max(len(a), 1), 0.05, 30.0))
            drawn = axes_k.scatter(m.position[:, 0], m.position[:, 1], c=a, s=size, vmin=0.0, vmax=top,
                                   cmap="viridis", linewidths=0)
            axes_k.set_aspect("equal")
            axes_k.set_title(m.label, fontsize=10)
            axes_k.set_xlabel("x [m]")
            axes_k.set_ylabel("y [m]")
        if drawn is not None:
            figure.colorbar(drawn, ax=list(axes[row]), shrink=0.85, label=label)
    suptitle(figure, title)
    return figure


def plain_log_labels(axes):
    """Tick labels as plain numbers (1.05, not 1.05 x 10^0) on a log axis whose range is
    within a decade, where matplotlib labels the minor ticks in scientific notation."""
    low, high = axes.get_ylim()
    if 0 < low and high < 10 * low:
        plain = matplotlib.ticker.FuncFormatter(lambda value, _: f"{value:g}")
        axes.yaxis.set_major_formatter(plain)
        axes.yaxis.set_minor_formatter(plain)


def label_panel(axes, x_label, y_label, title):
    """Axis labels, a panel title and a light grid on both scales."""
    axes.set_xlabel(x_label)
    axes.set_ylabel(y_label)
    axes.set_title(title, fontsize=10)
    axes.grid(True, which="both", alpha=0.3)


def suptitle(figure, title):
    """A figure title wrapped to the figure's width (about 11 characters per inch at this size)."""
    figure.suptitle(textwrap.fill(title, int(figure.get_figwidth() * 11)))


def save_png(figure, path, dpi=110):
    figure.savefig(path, dpi=dpi)
    plt.close(figure)
