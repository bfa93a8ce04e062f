"""The figures of a report (report.py) that particular results files call for:
probe-line profiles, point histories, the ring's angular error spectrum, the
Hertz contact pressure and load against approach, and the run health."""
import math

import numpy as np

from . import figures
from . import health_plot
from . import norms
from . import orders
from .figure_parts import FigureEntry, saved, split_label, time_text
from .report_rows import PARAMETER_LABELS
from .probes import (read_contact_pressure, read_error_spectrum, read_monitors, read_point_history, read_probe_lines,
                     read_scene_history, relative_energy_created)


def finest_completed(series):
    done = [c for c in series.cases if c.completed]
    return done[-1] if done else None


def profile_snapshots(line):
    """The last output and, when different, the output where the exact profile is
    largest (at the last output the exact motion may be at rest, as the ring's is)."""
    last = line.time.size - 1
    largest = int(np.nanargmax(np.nanmax(np.abs(line.exact), axis=1)))
    chosen = [last] if largest == last else [largest, last]
    return [figures.Snapshot(time_text(line.time[k]) if len(chosen) > 1 else "", line.simulated[k], line.exact[k])
            for k in chosen]


def case_geometry(case):
    """The results file's `geometry` attribute ("plane-strain" or "axisymmetric"), or None."""
    return case.attribute("geometry", None)  # decoded as read (results.plain)


def profile_figure(study, all_series, directory):
    panels, line, geometry = [], None, None
    for series in all_series:
        case = finest_completed(series)
        lines = read_probe_lines(case.results_path) if case else []
        if not lines or lines[0].time.size == 0:
            continue
        line, geometry = lines[0], case_geometry(case)
        panels.append(figures.ProfilePanel(f"{series.label}\n{case.keys[series.refine]} {series.refine}",
                                           line.positions, profile_snapshots(line)))
    if not panels:
        return None
    unit = norms.QUANTITY_UNITS.get(line.quantity, "")
    label = norms.quantity_label(line.quantity, geometry)
    figure = figures.profiles(panels, f"{study}: {label} along probe line {line.name}",
                              PARAMETER_LABELS.get(line.parameter, line.parameter), f"{label} [{unit}]", unit)
    path = saved(figure, directory, study, 'profile', line.name)
    return FigureEntry(study, path, f"{study}: simulated (markers) and exact (lines) {label} along probe line "
                                    f"{line.name} at the last output and where the exact profile is largest, finest "
                                    f"completed case of each series; below: simulated - exact.")


def history_figure(study, all_series, directory):
    panels, history, geometry = [], None, None
    for series in all_series:
        case = finest_completed(series)
        found = read_point_history(case.results_path) if case else None
        if found is None or found.time.size == 0:
            continue
        history, geometry = found, case_geometry(case)
        where = ", ".join(f"{x:.3g}" for x in np.ravel(history.reference_position))
        panels.append(figures.ProfilePanel(f"{series.label}\n{case.keys[series.refine]} {series.refine}, "
                                           f"point ({where}) m", history.time,
                                           [figures.Snapshot("", history.simulated, history.exact)]))
    if not panels:
        return None
    unit = norms.QUANTITY_UNITS.get(history.quantity, "")
    label = norms.quantity_label(history.quantity, geometry)
    figure = figures.profiles(panels, f"{study}: {label} at material point {history.name} over time",
                              "time t [s]", f"{label} [{unit}]", unit, markers=False)
    path = saved(figure, directory, study, 'history', history.name)
    return FigureEntry(study, path, f"{study}: {label} at material point {history.name} after every step, finest "
                                    f"completed case of each series, against the exact motion; below: "
                                    f"simulated - exact.")


def spectrum_figure(study, all_series, styles, directory):
    panels, quantity, floors = {}, "", {}
    for series in all_series:
        candidates = [c for c in series.cases if c.results is not None]
        chosen = next(((c, s) for c in reversed(candidates) for s in [read_error_spectrum(c.results_path)] if s),
                      None)
        if chosen is None:
            continue
        case, spectrum = chosen
        quantity = spectrum.quantity
        method, problem = split_label(series)
        label = (f"{method or series.label}, {case.keys[series.refine]} {series.refine}, "
                 f"{time_text(spectrum.time[-1])}")
        if not case.completed:
            label += f" ({case.status})"
        curve = figures.Curve(label, np.arange(spectrum.amplitude.shape[1]), spectrum.amplitude[-1],
                              styles[series.label])
        panels.setdefault(problem, []).append(curve)
        if quantity == "angular_displacement":
            # an angle's round-off: (ROUNDOFF_ULPS + steps) ulps of pi (orders.roundoff_floor)
            steps = float(case.attribute("steps", 0.0))
            floor = orders.roundoff_floor(int(steps) if math.isfinite(steps) else 0, math.pi)
            floors[problem] = max(floors.get(problem, 0.0), floor)
    if not panels:
        return None
    unit = norms.QUANTITY_UNITS.get(quantity, "")
    label = norms.QUANTITY_LABELS.get(quantity, quantity)
    figure = figures.error_spectra(list(panels.items()), f"{study}: angular spectrum of the {label} error on the "
                                   f"material circle at the last output", f"amplitude of mode m [{unit}]", floors)
    path = saved(figure, directory, study, 'spectrum')
    return FigureEntry(study, path, f"{study}: amplitude of angular mode m of the {label} error around the material "
                                    f"circle (/probes/circle/error_spectrum) at the last output, finest case of each "
                                    f"series that has one, one marker a mode; the exact motion is axisymmetric, so "
                                    f"m > 0 is lost axisymmetry" + (f"; the round-off floor of an angle, "
                                    f"({orders.ROUNDOFF_ULPS} + steps) ulps of pi, dotted (or named where it lies "
                                    f"below the axis): no mode below it means anything, and the axis starts a decade "
                                    f"under the smallest mode above it" if floors else "") + ".")


def level_label(series, case):
    return f"{series.refine}={case.keys[series.refine]}"


def level_styles(series):
    """Colour and marker by a case's place in its series (coarse first), the same in
    the contact-pressure and load-approach figures."""
    return {c.id: figures.Style(figures.COLOURS[k % len(figures.COLOURS)], figures.MARKERS[k % len(figures.MARKERS)])
            for k, c in enumerate(series.cases)}


def contact_extent(x, exact):
    """The largest |x| where the exact pressure is nonzero (NaN when it is zero everywhere)."""
    x, p = np.asarray(x, float), np.asarray(exact, float)
    on = np.isfinite(p) & (p > 0)
    return float(np.max(np.abs(x[on]))) if on.any() else float("nan")


def exact_pressure_curve(label, x, exact, x_max, p0=None, a=None):
    """The exact profile in mm and MPa up to x_max: Hertz's ellipse p0 sqrt(1 - x^2/a^2)
    drawn densely from the (p0, a) the results file holds for that time (returned with
    it), else (no load, or a file written before it held them) the stored values at the
    cell midpoints."""
    if p0 is None or a is None or not (p0 > 0 and a > 0):
        keep = np.abs(x) <= x_max
        return figures.Curve(f"exact, {label}", x[keep] * 1e3, exact[keep] / 1e6), None
    theta = np.linspace(0.0, 0.5 * np.pi, 200)
    side = np.concatenate([a * np.sin(theta), [max(x_max, a)]])
    pressure = np.concatenate([p0 * np.cos(theta), [0.0]])
    if np.min(x) < 0:
        side, pressure = np.concatenate([-side[::-1], side]), np.concatenate([pressure[::-1], pressure])
    return figures.Curve(f"Hertz at the load of {label}", side * 1e3, pressure / 1e6), (p0, a)


def contact_pressure_figure(study, all_series, directory):
    """Simulated contact pressure at each case's last output (markers, one series per
    level) against the exact curve of the series' finest case, x up to twice its
    contact half-width; None when no case has /probes/contact_pressure."""
    found = []
    for series in all_series:
        profiles = [(c, p) for c in series.cases if c.results is not None
                    for p in [read_contact_pressure(c.results_path)] if p is not None]
        if profiles:
            found.append((series, profiles))
    if not found:
        return None
    last_times = [p.time[-1] for _, profiles in found for _, p in profiles]
    common = max(last_times)
    panels = []
    for series, profiles in found:
        styles = level_styles(series)
        finest_case, finest = profiles[-1]
        extent = contact_extent(finest.x, finest.exact[-1])
        x_max = 2.0 * extent if extent > 0 else float(np.max(np.abs(finest.x)))
        curves = []
        for case, profile in profiles:
            keep = np.abs(profile.x) <= x_max * (1.0 + 1e-9)
            label = level_label(series, case)
            if not math.isclose(profile.time[-1], common) or not case.completed:
                label += f" ({case.status}, {time_text(profile.time[-1])})"
            curves.append(figures.Curve(label, profile.x[keep] * 1e3, profile.pressure[-1][keep] / 1e6,
                                        styles[case.id]))
        exact, ellipse = exact_pressure_curve(
            level_label(series, finest_case), finest.x, finest.exact[-1], x_max,
            None if finest.peak_pressure is None else finest.peak_pressure[-1],
            None if finest.half_width is None else finest.half_width[-1])
        title, marks = series.label, []
        if ellipse is not None:
            p0, a = ellipse
            title += f"\nHertz at {level_label(series, finest_case)}: p0 = {p0 / 1e6:.4g} MPa, a = {a * 1e3:.4g} mm"
            marks = [(a * 1e3, "a")]
        panels.append(figures.LinePanel(title, curves, exact, marks))
    when = time_text(common) if all(math.isclose(t, common) for t in last_times) else "the last output of each case"
    # In r-z the distance from the axis is the radius r, and a the contact's radius.
    radial = all(case.attribute("geometry", "") == "axisymmetric" for _, profiles in found for case, _ in profiles)
    x, width = ("r", "contact radius") if radial else ("x", "half-width")
    figure = figures.pressure_profiles(panels, f"{study}: contact pressure at {when}",
                                       f"distance {x} from the axis [mm]", "contact pressure [MPa]")
    path = saved(figure, directory, study, 'contact-pressure')
    refine = found[0][0].refine
    return FigureEntry(study, path, f"{study}: contact pressure on the plate [MPa] against distance {x} from the axis "
                                    f"[mm] at {when} (/probes/contact_pressure); markers: simulated at the cell "
                                    f"midpoints, one series per {refine} level; line: the exact (Hertz) pressure "
                                    f"p0 sqrt(1 - {x}^2/a^2) at the load the finest case measured, dotted at its "
                                    f"{width} a; {x} up to twice the largest {x} where that exact pressure is "
                                    f"nonzero.")


def load_approach_figure(study, all_series, directory):
    """Load against approach from /probes/history after every step, one line per case;
    None when no case has a history with datasets `approach` and `load`."""
    panels = []
    for series in all_series:
        styles = level_styles(series)
        curves = []
        for case in series.cases:
            history = read_scene_history(case.results_path) if case.results is not None else None
            if history is None or not {"approach", "load"} <= history.values.keys():
                continue
            label = level_label(series, case)
            if not case.completed:
                label += f" ({case.status} at {time_text(history.time[-1])})"
            curves.append(figures.Curve(label, history.values["approach"] * 1e6, history.values["load"] / 1e6,
                                        styles[case.id]))
        if curves:
            panels.append(figures.LinePanel(series.label, curves))
    if not panels:
        return None
    figure = figures.histories(panels, f"{study}: load against approach", "approach [µm]", "load [MN/m]")
    path = saved(figure, directory, study, 'load-approach')
    return FigureEntry(study, path, f"{study}: load per unit length [MN/m] against approach [µm] after every step "
                                    f"(/probes/history), one line per case, by {all_series[0].refine}.")


HEALTH_MAX_CASES = 12          # with more cases than this the run-health figure draws a selection


def health_selection(cases):
    """The cases the run-health figure draws, in the order given, and whether that is
    a selection: all of them when there are at most HEALTH_MAX_CASES; else, so that
    the figure stays readable, two per value of the `method` key: the finest
    completed case (smallest h; the last listed on a tie) and the finest case that
    did not complete (smallest h; the earliest failure on a tie)."""
    if len(cases) <= HEALTH_MAX_CASES:
        return list(cases), False

    def failure_time(case):
        t = float(case.attribute("failure_time"))
        return t if math.isfinite(t) else float("inf")

    finest, failed = {}, {}
    for case in cases:
        method = str(case.keys.get("method", ""))
        if case.completed:
            if method not in finest or case.h <= finest[method].h:
                finest[method] = case
        elif method not in failed or (case.h, failure_time(case)) < (failed[method].h, failure_time(failed[method])):
            failed[method] = case
    kept = {c.id for c in finest.values()} | {c.id for c in failed.values()}
    return [c for c in cases if c.id in kept], True


def health_label(series, case, monitors):
    """The series' keys and the case's level, as the other figures label cases; a
    case that did not complete adds its status, failure time and reason. Returns
    (label, failure time or NaN)."""
    # a lone series without a method key is labelled "all cases" (series.py): its level says enough
    label = level_label(series, case) if series.label == "all cases" else f"{series.label}, {level_label(series, case)}"
    if case.completed:
        return label, float("nan")
    # failure_time is NaN when the file does not say (results-format.md): then the last time reached or recorded
    stop = next((t for t in (float(case.attribute("failure_time")), case.time_reached, float(monitors.time[-1]))
                 if math.isfinite(t)), float("nan"))
    reason = case.attribute("failure_reason", "")
    when = f" at {time_text(stop)}" if math.isfinite(stop) else ""
    return f"{label} ({case.status}{when}{': ' + reason if reason else ''})", stop


def health_figure(study, all_series, directory):
    """The run's health over time from /probes/monitors (results-format.md,
    "/probes/monitors"), one line per case; None when no case of the study has the
    group (results files written before the monitors existed)."""
    found, without = [], 0
    for series in all_series:
        for case in series.cases:
            monitors = read_monitors(case.results_path) if case.results is not None else None
            if monitors is not None:
                found.append((series, case, monitors))
            elif case.results is not None:
                without += 1
    if not found:
        return None
    chosen, selected = health_selection([case for _, case, _ in found])
    chosen_ids = {c.id for c in chosen}
    curves = []
    for series, case, monitors in found:
        if case.id not in chosen_ids:
            continue
        label, stop = health_label(series, case, monitors)
        # one colour and marker per drawn case, as level_styles gives each case of a series its own
        k = len(curves)
        style = figures.Style(figures.COLOURS[k % len(figures.COLOURS)], figures.MARKERS[k % len(figures.MARKERS)])
        curves.append(health_plot.HealthCurve(label, monitors.time, relative_energy_created(monitors),
                                          monitors.column("min_J"), monitors.column("max_J"),
                                          monitors.column("max_speed_over_wave_speed"),
                                          monitors.column("max_domain_distortion"), style, stop,
                                          monitors.column("cfl_step") / monitors.column("stable_step"),
                                          monitors.column("max_wave_speed_ratio"),
                                          monitors.column("max_basis_stiffening"),
                                          monitors.column("uncovered_fraction"),
                                          monitors.column("inside_fraction")))
    figure = health_plot.run_health(curves, f"{study}: run health at the output times")
    path = saved(figure, directory, study, 'health')
    caption = (f"{study}: the run's health at each output time (/probes/monitors), one line per case. From the top: "
               "the energy balance error, abs(energy_created) over energy_scale, the solver's scale of its blow-up "
               "and health tests (the larger of the initial energy and the largest abs(work) any one work_* term "
               "has done by then; log scale; absent from results files written before it); "
               "min J and max J over the particles (the lower and upper line of a case's colour), dotted at J = 0; "
               "the largest particle speed over its wave speed; the largest CPDI domain distortion (1: a square "
               "domain; log scale; none for linear MPM); where the runs have domains and an exact motion "
               "(/probes/coverage), the share of the material that no particle domain covers, in percent of the "
               "body: all of it (solid) and where the domain holding it at the start lay away from the body's "
               "sides (dotted), the holes that open between domains rather than at a side; where the results "
               "files have them, what lifts the signal "
               "speed max(max(c_p, k_p c0_p) + |v_p|) that sets the CFL step (cfl h over it) above the small-strain "
               "wave speed c0 at the reference density: the particle's state and density, max c_p / c0 (solid), and the basis, max k_p (dotted; CPDI's corner "
               "interpolation, the total formulation's compressed cell), log scale; where the runs measured it "
               "(stable_step_iterations), the "
               "step the CFL rule takes over the measured stable step 2 / omega_max of the linearized grid motion, "
               "unstable above 1 (dotted). x: the failure time of a failed case, at the height of its "
               "last recorded value (dotted from its last output).")
    if selected:
        caption += (f" {len(chosen)} of the {len(found)} cases with monitors are drawn: for each method the finest "
                    f"completed case and the finest case that did not complete (the earliest failure on a tie); the "
                    f"stability map shows every case.")
    folded = []
    for series, case, monitors in found:
        counts = monitors.column("folded_domains")
        if np.any(counts > 0):  # NaN (a file without the column) compares False
            first = int(np.argmax(counts > 0))
            folded.append(f"{health_label(series, case, monitors)[0]}: {int(np.nanmax(counts))} at most, from "
                          f"{time_text(float(monitors.time[first]))}")
    if folded:
        caption += (" CPDI corner domains turned over (folded_domains; their corners no longer bound the material, "
                    "results-format.md) in " + "; ".join(folded) + ".")
    if without:
        caption += f" {without} case(s) of the study have results without /probes/monitors (written before them)."
    return FigureEntry(study, path, caption)
