"""The report's first figure: every series the gate checked, its observed order
with its 95 % interval against the expected band (one row a series, green
where it holds, red where it falls short), and beside it the series judged on
their error alone, the largest error over its limit (log scale, the limit at
1). A reader sees at once which series sit inside their band."""
import math

from . import figures
from .figure_parts import FigureEntry, saved
from .figures import plt

HOLDS, SHORT = "#1a7f37", "#c62828"


def _label(verdict):
    expect = verdict.expectation
    series = verdict.series.label if verdict.series is not None else "no case"
    return f"#{verdict.number} {expect['study']}: {series}, {expect['norm']}"


def _largest_error(verdict):
    errors = [level.error for level in verdict.levels if not level.reason and math.isfinite(level.error)]
    return max(errors) if errors else float("nan")


def verdict_figure(verdicts, directory, suite_name):
    """The figure over the gate's verdicts (None without verdicts)."""
    if not verdicts:
        return None
    ordered = [v for v in verdicts if "order" in v.expectation]
    bounded = [v for v in verdicts if "order" not in v.expectation and "max_error" in v.expectation]
    panels = [p for p in (ordered, bounded) if p]
    if not panels:
        return None
    rows = max(len(p) for p in panels)
    # Each panel as wide as its longest row label (about 0.06 inch a character at size 8) and 4 inches more.
    width = sum(0.06 * max(len(_label(v)) for v in p) + 4.0 for p in panels)
    figure, axes = plt.subplots(1, len(panels), figsize=(width, 0.42 * rows + 1.6), squeeze=False,
                                constrained_layout=True)
    axes = list(axes[0])
    if ordered:
        panel = axes.pop(0)
        for y, v in enumerate(ordered):
            expected, tolerance = float(v.expectation["order"]), float(v.expectation["tolerance"])
            colour = HOLDS if v.passed else SHORT
            panel.add_patch(plt.Rectangle((expected - tolerance, y - 0.35), 2 * tolerance, 0.7, facecolor="#dddddd",
                                          edgecolor="none"))
            if math.isfinite(v.fit.order) and not v.floor:
                low, high = v.fit.ci_low, v.fit.ci_high
                if math.isfinite(low):
                    panel.plot([low, high], [y, y], color=colour, linewidth=2.0)
                panel.plot([v.fit.order], [y], marker="o", color=colour, markersize=7, linestyle="none")
            else:
                why = f"no order: {v.floor}" if v.floor else "no order"
                panel.text(expected, y, why, ha="center", va="center", fontsize=8, color=colour)
        # patches do not widen the axes: the bands and the fits set the range
        ends = [float(v.expectation["order"]) + sign * float(v.expectation["tolerance"]) for v in ordered
                for sign in (-1, 1)]
        ends += [x for v in ordered if not v.floor for x in (v.fit.order, v.fit.ci_low, v.fit.ci_high)
                 if math.isfinite(x)]
        margin = 0.1 * (max(ends) - min(ends)) + 0.2
        panel.set_xlim(min(ends) - margin, max(ends) + margin)
        panel.set_yticks(range(len(ordered)), [_label(v) for v in ordered], fontsize=8)
        panel.set_ylim(len(ordered) - 0.5, -0.5)
        panel.set_xlabel("observed order p (dot) with its 95 % interval (bar); expected band shaded")
        panel.set_title("series judged by their order", fontsize=10)
        panel.grid(True, axis="x", alpha=0.3)
    if bounded:
        panel = axes.pop(0)
        ratios = [_largest_error(v) / float(v.expectation["max_error"]) for v in bounded]
        for y, (v, ratio) in enumerate(zip(bounded, ratios)):
            colour = HOLDS if v.passed else SHORT
            if ratio > 0 and math.isfinite(ratio):
                panel.plot([ratio], [y], marker="o", color=colour, markersize=7, linestyle="none")
            else:
                panel.text(1.0, y, "no usable level", ha="center", va="center", fontsize=8, color=colour)
        panel.axvline(1.0, color="black", linestyle=":", linewidth=1.0)
        finite = [r for r in ratios if r > 0 and math.isfinite(r)]
        low = min(finite + [1.0]) / 3.0
        high = max(finite + [1.0]) * 3.0
        panel.set_xscale("log")
        panel.set_xlim(low, high)
        figures.plain_log_labels(panel)
        panel.set_yticks(range(len(bounded)), [_label(v) for v in bounded], fontsize=8)
        panel.set_ylim(len(bounded) - 0.5, -0.5)
        panel.set_xlabel("largest error over its limit max_error (holds left of 1)")
        panel.set_title("series judged by their error", fontsize=10)
        panel.grid(True, axis="x", which="both", alpha=0.3)
    held = sum(v.passed for v in verdicts)
    figures.suptitle(figure, f"{suite_name}: {held} of {len(verdicts)} series hold their expectation")
    path = saved(figure, directory, "gate", "verdicts")
    caption = (f"{suite_name}: every series the gate checked, one row each (#: the expectation's place in "
               "suite.toml), green where it holds and red where it falls short. Left: the observed least-squares "
               "order (dot) and its 95 % interval (bar; none with two levels) against the expected band (grey); a "
               "series at round-off or settling has no order. Right: for expectations on the error alone, the "
               "largest error of the usable levels over max_error.")
    return FigureEntry("gate", path, caption)
