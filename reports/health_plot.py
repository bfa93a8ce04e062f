"""The run-health figure: four panels (more with the holes between the domains,
what slows the step and the measured stable step) over time from
/probes/monitors and /probes/coverage, one line per case: the energy balance
error over its scale, J's range, the largest speed over the wave speed and the
largest CPDI domain distortion; a failed case's failure time marked x."""
import math
from dataclasses import dataclass, field

import matplotlib
import numpy as np

from . import figures
from .figures import COLOURS, Style, plt


@dataclass
class HealthCurve:
    """One case's /probes/monitors, as the run-health figure draws them (values at `time`)."""
    label: str
    time: np.ndarray
    energy_error: np.ndarray      # abs(energy_created) / scale (probes.relative_energy_created)
    min_J: np.ndarray
    max_J: np.ndarray
    speed_ratio: np.ndarray       # max_speed_over_wave_speed
    distortion: np.ndarray        # max_domain_distortion; NaN for linear MPM
    style: Style = field(default_factory=Style)
    stopped_at: float = float("nan")   # failure time of a failed case (marked x); NaN for a completed one
    # cfl_step / stable_step: the step the CFL rule takes over the measured stable step 2 / omega_max
    # (stable_step_iterations > 0); None, or NaN at every time, where not measured
    step_ratio: np.ndarray = None
    # max_wave_speed_ratio and max_basis_stiffening (results-format.md): what lifts the CFL step's
    # signal speed above the small-strain wave speed; None, or NaN at every time, in older files
    wave_ratio: np.ndarray = None
    basis_stiffening: np.ndarray = None
    # uncovered_fraction and inside_fraction of /probes/coverage: the share of the material in
    # holes between the domains, all and away from the body's sides; None, or NaN at every time,
    # without domains or an exact motion
    holes: np.ndarray = None
    holes_inside: np.ndarray = None


def _has_finite(values):
    return values is not None and np.isfinite(np.asarray(values, float)).any()


LINE_STYLES = ["-", "--", "-.", ":"]
# A case with this many output times or fewer is drawn as markers, without lines.
FEW_OUTPUT_TIMES = 2


def run_health(curves, title):
    """Four panels sharing the time axis, one line per curve (colour and marker from
    its style; the line style changes after every len(COLOURS) curves so that no two
    look alike): the energy balance error (log), min J and max J with J = 0 dotted,
    the largest speed over wave speed, the largest domain distortion (log; a note
    instead when every value is NaN, as for linear MPM); one more when any curve
    has a finite `holes`: the share of the material in holes between the domains
    in percent, all (solid) and away from the body's sides (dotted); one more when any curve
    has a finite wave_ratio or basis_stiffening: what lifts the CFL step's signal
    speed above the small-strain wave speed, the material's state (solid) and the
    basis (dotted), log; and one more when any curve has a finite step_ratio: the
    step over the measured stable step, dotted at 1, above which the linearized
    step is unstable. A curve with a finite `stopped_at` gets an x there, at the
    height of its last drawn value."""
    with_ratio = any(_has_finite(c.step_ratio) for c in curves)
    with_lift = any(_has_finite(c.wave_ratio) or _has_finite(c.basis_stiffening) for c in curves)
    with_holes = any(_has_finite(c.holes) for c in curves)
    rows = 4 + with_holes + with_lift + with_ratio
    figure, axes = plt.subplots(rows, 1, figsize=(10.5, 2.75 * rows), sharex=True, squeeze=False,
                                constrained_layout=True)
    energy, jacobian, speed, distortion = axes[:4, 0]
    holes = axes[4, 0] if with_holes else None
    lift = axes[4 + with_holes, 0] if with_lift else None
    ratio = axes[rows - 1, 0] if with_ratio else None
    drawn = {energy: False, distortion: False}
    for k, curve in enumerate(curves):
        t = np.asarray(curve.time, float)
        line = dict(color=curve.style.colour, marker=curve.style.marker, markersize=4, linewidth=1.2,
                    linestyle=LINE_STYLES[(k // len(COLOURS)) % len(LINE_STYLES)])
        if t.size <= FEW_OUTPUT_TIMES:
            # Two points joined read as a trend the run never showed: markers alone.
            line.update(linestyle="none", markersize=7)
        # log panels: a value that is not positive (no error at all, or NaN) is left out of the line
        for panel, values in ((energy, curve.energy_error), (distortion, curve.distortion)):
            positive = _positive(values)
            if np.isfinite(positive).any():
                panel.plot(t, positive, **line)
                _mark_stop(panel, curve, t, positive)
                drawn[panel] = True
        for values in (curve.min_J, curve.max_J):
            jacobian.plot(t, values, **line)
            _mark_stop(jacobian, curve, t, values)
        # every curve has a line here (NaN values draw nothing): the legend is taken from it
        speed.plot(t, curve.speed_ratio, label=curve.label, **line)
        _mark_stop(speed, curve, t, curve.speed_ratio)
        if holes is not None:
            for values, style in ((curve.holes, line["linestyle"]), (curve.holes_inside, ":")):
                if _has_finite(values):
                    percent = 100.0 * np.asarray(values, float)
                    holes.plot(t, percent, **_with_style(line, style))
                    _mark_stop(holes, curve, t, percent)
        if lift is not None:
            for values, style in ((curve.wave_ratio, line["linestyle"]), (curve.basis_stiffening, ":")):
                if _has_finite(values):
                    lift.plot(t, values, **_with_style(line, style))
                    _mark_stop(lift, curve, t, values)
        if ratio is not None and curve.step_ratio is not None:
            ratio.plot(t, curve.step_ratio, **line)
            _mark_stop(ratio, curve, t, curve.step_ratio)
    jacobian.axhline(0.0, color="black", linestyle=":", linewidth=1.0)
    jacobian.annotate("J = 0", (0.0, 0.0), xycoords=("axes fraction", "data"), xytext=(3, 3),
                      textcoords="offset points", fontsize=8)
    no_domains = all(np.isnan(np.asarray(c.distortion, float)).all() for c in curves)
    for panel, note in ((energy, "no nonzero energy balance error"),
                        (distortion, "no CPDI domains" if no_domains else "no finite distortion")):
        if drawn[panel]:
            panel.set_yscale("log")
            figures.plain_log_labels(panel)
        else:
            panel.text(0.5, 0.5, note, transform=panel.transAxes, ha="center", va="center", color="grey")
    figures.label_panel(energy, "", "|energy created| / scale", "energy balance error")
    figures.label_panel(jacobian, "", "J = det F", "min J and max J over the particles")
    figures.label_panel(speed, "", "max |v| / c", "largest particle speed over its wave speed")
    figures.label_panel(distortion, "" if holes is not None or lift is not None or ratio is not None else "time t [s]",
                         "max domain distortion", "largest domain distortion (1: square)")
    if holes is not None:
        holes.set_ylim(bottom=0.0)
        figures.label_panel(holes, "" if lift is not None or ratio is not None else "time t [s]",
                            "material in holes [%]",
                            "material in holes between domains: all (solid), away from the sides (dotted)")
    if lift is not None:
        lift.axhline(1.0, color="black", linestyle="-", linewidth=0.6, alpha=0.5)
        lift.set_yscale("log")
        figures.plain_log_labels(lift)
        figures.label_panel(lift, "" if ratio is not None else "time t [s]", "max c / c0, max k",
                             "what slows the step: the particle's state and density, max c_p / c0 (solid), and the basis, "
                     "max k_p (dotted)")
    if ratio is not None:
        ratio.axhline(1.0, color="black", linestyle=":", linewidth=1.0)
        ratio.set_ylim(bottom=0.0)
        figures.label_panel(ratio, "time t [s]", "dt / (2 / omega_max)",
                             "the CFL step over the measured stable step (unstable above 1)")
    handles, labels = speed.get_legend_handles_labels()
    if any(math.isfinite(c.stopped_at) for c in curves):
        handles.append(matplotlib.lines.Line2D([], [], color="black", marker="x", linestyle="none", markersize=8,
                                               markeredgewidth=2))
        labels.append("failure time of a failed case")
    if handles:
        energy.legend(handles, labels, fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    figures.suptitle(figure, title)
    return figure


def _with_style(line, style):
    """The line's settings with another line style, unless it draws markers alone."""
    return line if line["linestyle"] == "none" else {**line, "linestyle": style}


def _positive(values):
    """The values with those not finite and positive set to NaN (a gap on a log axis)."""
    values = np.asarray(values, float)
    return np.where(np.isfinite(values) & (values > 0), values, np.nan)


def _mark_stop(axes, curve, t, values):
    """An x at the curve's failure time, at the height of its last finite value, joined
    to that value by a dotted line when the run stopped after its last output."""
    finite = np.nonzero(np.isfinite(np.asarray(values, float)))[0]
    if not (math.isfinite(curve.stopped_at) and finite.size):
        return
    last_time, last_value = t[finite[-1]], values[finite[-1]]
    axes.plot([last_time, curve.stopped_at], [last_value, last_value], ":", color=curve.style.colour,
              linewidth=1.0)
    axes.plot([curve.stopped_at], [last_value], "x", color=curve.style.colour, markersize=9, markeredgewidth=2)
