#!/usr/bin/python3
"""Convergence report of a suite output directory, from its results files only.

Usage: /usr/bin/python3 reports/report.py DIR [-o OUT]      (default OUT = DIR/report)

Writes
  OUT/report.html   self-contained (figures embedded as base64 PNG, no external links)
  OUT/report.md     the same text, figures linked from OUT/figures/*.png
  OUT/orders.csv    one row per (study, refinement series, error norm, output time)
  OUT/gci.csv       Richardson extrapolation and GCI of each series' point-probe value

The columns of orders.csv are ORDERS_CSV_COLUMNS below; the report states them.

Norms are defined in reports/norms.py, orders, the classification rule and
the GCI in reports/orders.py, refinement series in reports/series.py.
"""
import argparse
import base64
import csv
import html
import math
import re
import sys
import textwrap
import time as clock
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np

import figures
import gate
import norms
import orders
import references
from results import (SuiteDirectoryError, lookup_error, read_contact_pressure, read_error_spectrum, read_monitors,
                     read_point_history, read_probe_lines, read_scene_history, read_suite, relative_energy_created)
from series import (DEFAULT_REFINE_KEY, floor_kind, floor_text, refined_size, refinement_series, roundoff_checks,
                    series_levels, size_name, steps_of, usable)

ORDERS_CSV_COLUMNS = (
    ("study", "the study"),
    ("series", "the keys that name the refinement series"),
    ("norm", "an /errors column"),
    ("unit", "its unit"),
    ("time", "output time [s]"),
    ("refine", "the key that refines"),
    ("levels", "its values at the usable levels, coarse first, ';'-separated"),
    ("h", "the size the refine key sets at those levels: cell size h [m]; h / particles_per_direction [m] for "
          "particles per direction; cfl h [m] for cfl; 1 / load_steps (reports/series.py: REFINED_SIZES)"),
    ("error", "the norm at those levels"),
    ("pairwise_orders", "orders between consecutive usable levels (empty at round-off)"),
    ("ls_order", "least-squares order (NaN at round-off)"),
    ("ci_low", "lower end of its 95% Student-t interval (NaN with two levels or at round-off)"),
    ("ci_high", "upper end"),
    ("classification", "round-off, settling, asymptotic, non-asymptotic, stalled, unchecked (2 levels) or too few levels"),
    ("finest_level", "refine value of the finest usable level"),
    ("finest_h", "its size (as h)"),
    ("finest_error", "its error"),
    ("left_out", "levels without a usable value at that time, and why"),
    ("relative_error", "each usable level's error over the exact signal the norm measures at that time (NaN where "
                       "not known; error_* and particle_relative_L2_integrated are relative already: signal 1)"),
    ("roundoff_floor", "each usable level's round-off floor, (256 + steps) ulps of the numbers the error is a "
                       "difference of, over the same signal: a level whose relative_error is at most this is at "
                       "round-off (reports/orders.py)"),
    ("settling", "each usable level's settling level over the same signal, the largest error the run's distance "
                 "from its static state at the end could leave (results.py: settling_scale; NaN for a run that "
                 "does not settle): a level whose relative_error is at most this is at the settling level"),
)
METHOD_KEYS = ("method", "scheme", "particles_per_direction", "cfl", "time_integration", "solver", "load_steps",
               "dilatation", "formulation")
PARAMETER_LABELS = {"reference_radius": "reference radius R [m]", "reference_r": "reference radius R [m]",
                    "reference_x": "reference X [m]", "reference_y": "reference Y [m]",
                    "reference_z": "reference Z [m]", "reference_position": "distance from the origin [m]"}


# ---------------------------------------------------------------- numbers


@dataclass(frozen=True)
class OrderRow:
    study: str
    series: object               # series.Series
    norm: str
    unit: str
    time: float
    at_end: bool
    levels: tuple                # usable series.Level, coarse first
    left_out: tuple              # the others
    pairwise: tuple
    fit: orders.OrderFit
    classification: str
    roundoff: tuple = ()         # series.RoundOff per usable level (None where its signal is not known)

    @property
    def has_order(self):
        """False for a series at round-off or at the settling level: its fitted
        numbers measure the rounding, or how far the solver stopped short."""
        return self.classification not in ("round-off", "settling")


@dataclass(frozen=True)
class GciRow:
    study: str
    series: object
    probe: str
    quantity: str
    time: float
    levels: tuple                # refine values, coarse first
    values: tuple                # f_3, f_2, f_1
    ratio: float
    convergence: orders.GridConvergence
    exact: float


def refine_key(suite, study):
    """The refine key of the study's first expectation that names one, else "cells"."""
    return next((e["refine"] for e in suite.expectations if isinstance(e, dict) and e.get("study") == study
                 and isinstance(e.get("refine"), str)), DEFAULT_REFINE_KEY)


def study_series(suite, study):
    return refinement_series(suite.cases_of(study), refine_key(suite, study), suite.varied_keys(study))


def expectation_times(suite, study):
    return [float(e["time"]) for e in suite.expectations
            if isinstance(e, dict) and e.get("study") == study and isinstance(e.get("time"), (int, float))]


def error_columns(cases):
    """Every /errors column of the cases, in first-seen order."""
    return list(dict.fromkeys(name for c in cases if c.results for name in c.results.errors))


def line_quantities(cases):
    merged = {}
    for case in cases:
        if case.results:
            merged.update(case.results.line_quantities)
    return merged


def series_end_time(series):
    times = [c.end_time for c in series.cases if math.isfinite(c.end_time)]
    return times[0] if times else float("nan")


def order_row(series, norm, unit, time, at_end):
    levels = series_levels(series, norm, time)
    good = usable(levels)
    h, error = [l.h for l in good], [l.error for l in good]
    pairwise = orders.pairwise_orders(h, error)
    checks = roundoff_checks(good, norm, time) if len(good) >= 2 else []
    return OrderRow(series.study, series, norm, unit, time, at_end, tuple(good),
                    tuple(l for l in levels if l.reason), tuple(pairwise),
                    orders.least_squares_order(h, error), orders.classify(pairwise, floor_kind(checks)),
                    tuple(checks))


def order_rows(suite):
    """Orders of every series of every study, for every norm, at the end time and
    at each output time an expectation of the study names."""
    rows = []
    for study in suite.study_names():
        cases = suite.cases_of(study)
        quantities = line_quantities(cases)
        for series in study_series(suite, study):
            end = series_end_time(series)
            times = [end] + [t for t in expectation_times(suite, study) if not math.isclose(t, end)]
            for norm in error_columns(cases):
                for t in dict.fromkeys(times):
                    rows.append(order_row(series, norm, norms.norm_unit(norm, quantities), t, t == end))
    return rows


def gci_rows(suite):
    """Roache's three-level study (reports/orders.py) of the point probe's simulated
    value on the three finest completed levels of each series with a constant
    refinement ratio, at the output time where the finest level's value is largest;
    the exact value is kept only to check the GCI band."""
    rows = []
    for study in suite.study_names():
        for series in study_series(suite, study):
            row = gci_row(series)
            if row is not None:
                rows.append(row)
    return rows


def gci_row(series):
    size = {c.id: refined_size(c, series.refine) for c in series.cases}
    finest = [c for c in series.cases if c.completed and math.isfinite(size[c.id])][-3:]
    if len(finest) < 3:
        return None
    ratio = size[finest[0].id] / size[finest[1].id]
    # A constant refinement ratio above 1 (a series whose size does not fall has none).
    if not ratio > 1.0 or not math.isclose(ratio, size[finest[1].id] / size[finest[2].id], rel_tol=1e-6):
        return None
    histories = [read_point_history(c.results_path) for c in finest]
    if any(h is None or h.time.size == 0 for h in histories):
        return None
    output_times = np.asarray(finest[-1].attribute("output_times", []), float).ravel()
    if output_times.size == 0:
        output_times = np.asarray([finest[-1].end_time])
    fine = histories[-1]
    at = float(max(output_times, key=lambda t: abs(np.interp(t, fine.time, fine.simulated))))
    values = tuple(float(np.interp(at, h.time, h.simulated)) for h in histories)
    convergence = orders.grid_convergence(values[0], values[1], values[2], ratio)
    if point_changes_at_roundoff(finest, fine, values):
        nan = float("nan")
        convergence = orders.GridConvergence(nan, "round-off", nan, nan, nan, nan)
    return GciRow(series.study, series, fine.name, fine.quantity, at,
                  tuple(c.keys[series.refine] for c in finest), values, ratio, convergence,
                  float(np.interp(at, fine.time, fine.exact)))


def point_changes_at_roundoff(cases, history, values):
    """True when a change of the point's value between consecutive levels is no
    larger than the round-off floor of reports/orders.py (the point's |X| for a
    length, pi for an angle, over the most steps any of the cases took): such
    changes measure rounding, and Roache's order of them means nothing."""
    position = np.ravel(np.asarray(history.reference_position, float))
    if history.quantity == "angular_displacement":
        size = math.pi
    elif position.size >= 2 and np.all(np.isfinite(position[:2])):
        size = float(np.hypot(position[0], position[1]))
    else:
        return False
    floor = orders.roundoff_floor(max((steps_of(c) for c in cases), default=0), size)
    return any(abs(coarse - fine) <= floor for coarse, fine in zip(values, values[1:]))


def stored_norm_check(suite):
    """(cases checked, largest relative difference) between eq. 3.1 recomputed from
    the probe arrays and the stored L1_<line> columns."""
    checked, largest = 0, 0.0
    for case in suite.cases:
        if case.results is None:
            continue
        try:
            lines = read_probe_lines(case.results_path)
        except (OSError, KeyError, ValueError, TypeError):
            continue  # a damaged probe group: that case is not checked (its figures say why)
        for line in lines:
            stored = case.results.errors.get("L1_" + line.name)
            if stored is not None:
                recomputed = norms.probe_line_l1(line.simulated, line.exact)
                largest = max(largest, norms.stored_l1_discrepancy(stored, recomputed[: stored.size]))
        checked += 1
    return checked, largest


# ---------------------------------------------------------------- figures


@dataclass(frozen=True)
class FigureEntry:
    study: str
    path: Path                   # None for a figure left out (the caption says why)
    caption: str


def split_label(series):
    method = {k: v for k, v in series.label_keys.items() if k in METHOD_KEYS}
    problem = {k: v for k, v in series.label_keys.items() if k not in METHOD_KEYS}
    join = lambda keys: ", ".join(f"{k}={v}" for k, v in keys.items())  # noqa: E731
    return join(method), join(problem)


def series_styles(all_series):
    """Colour by method settings, marker by problem keys, the same in every figure of a study."""
    methods = list(dict.fromkeys(split_label(s)[0] for s in all_series))
    problems = list(dict.fromkeys(split_label(s)[1] for s in all_series))
    return {s.label: figures.Style(figures.COLOURS[methods.index(split_label(s)[0]) % len(figures.COLOURS)],
                                   figures.MARKERS[problems.index(split_label(s)[1]) % len(figures.MARKERS)])
            for s in all_series}


def figure_norms(suite, study, cases):
    """(norm, time or None for the end time) pairs drawn against h: those the study's
    expectations name, the first probe line's L1, particle_L2 and the time-integrated
    relative L2 at the end time
    (an expectation's time equal to the study's one end time counts as the end time)."""
    ends = {c.end_time for c in cases if math.isfinite(c.end_time)}
    pairs = []
    for e in suite.expectations:
        if isinstance(e, dict) and e.get("study") == study and isinstance(e.get("norm"), str):
            time = e.get("time")
            explicit = isinstance(time, (int, float)) and not (len(ends) == 1 and math.isclose(time, min(ends)))
            pairs.append((e["norm"], float(time) if explicit else None))
    first_line = next(iter(line_quantities(cases)), None)
    pairs += [(f"L1_{first_line}", None), ("particle_L2", None)] if first_line else [("particle_L2", None)]
    pairs.append(("particle_relative_L2_integrated", None))
    columns = error_columns(cases)
    return [p for p in dict.fromkeys(pairs) if p[0] in columns]


def slug(*parts):
    return re.sub(r"[^A-Za-z0-9_.=-]+", "_", "-".join(str(p) for p in parts)).strip("_")


def time_text(t):
    return f"t = {t:g} s"


def error_figure(study, norm, time, rows, styles, quantities, directory):
    chosen = [r for r in rows if r.study == study and r.norm == norm
              and (r.at_end if time is None else math.isclose(r.time, time))]
    if not chosen:
        return None
    times = sorted({r.time for r in chosen})
    when = time_text(times[0]) if len(times) == 1 else "the end time"
    # A series at round-off or at the settling level is drawn without a fit, and its legend says why.
    curves = [figures.Curve(r.series.label if r.has_order else f"{r.series.label}: {r.classification}, no order",
                            [l.h for l in r.levels], [l.error for l in r.levels], styles[r.series.label],
                            r.fit if r.has_order else None) for r in chosen]
    unit = chosen[0].unit
    against = size_name(chosen[0].series.refine)
    figure = figures.error_against_h(curves, f"{study}: {norm} at {when}", f"{norm} [{unit}]", against)
    path = directory / f"{slug(study, 'error', norm, 'end' if time is None else time)}.png"
    figures.save_png(figure, path)
    missing = [r.series.label for r in chosen if not r.levels]
    caption = (f"{study}: {norms.describe_norm(norm, quantities)} [{unit}] at {when} against {against}; "
               f"dashed: least-squares fit over every usable level drawn (an expectation naming fewer levels "
               f"fits those, as the verdict's levels column says); grey: slopes 1 and 2.")
    at_floor = [r for r in chosen if not r.has_order]
    if at_floor:
        caption += " No order, errors at " + "; ".join(
            f"{floor_text(r.series.refine, r.roundoff)} ({r.series.label})" for r in at_floor) + "."
    if missing:
        caption += f" No usable level: {'; '.join(missing)}."
    return FigureEntry(study, path, caption)


def work_precision_figure(study, all_series, norm, unit, styles, directory):
    panels = {}
    for series in all_series:
        method, problem = split_label(series)
        points = [(c.wall_time_s, lookup_error(c, norm, c.end_time)[0]) for c in series.cases if c.completed]
        curve = figures.Curve(method or series.label, [p[0] for p in points], [p[1] for p in points],
                              styles[series.label])
        panels.setdefault(problem, []).append(curve)
    end = series_end_time(all_series[0])
    figure = figures.work_precision(list(panels.items()), f"{study}: work against precision, {norm} at the end "
                                    f"time", f"{norm} at t = {end:g} s [{unit}]")
    path = directory / f"{slug(study, 'work-precision')}.png"
    figures.save_png(figure, path)
    return FigureEntry(study, path, f"{study}: {norm} at the end time against wall time of the time loop for the "
                                    f"completed cases, one curve per method setting across "
                                    f"{all_series[0].refine}; circled: Pareto front (no case is both faster and "
                                    f"more accurate).")


def stability_cell(case):
    if case.results is None:
        return figures.StabilityCell(float("nan"), case.status, stopped=True)
    reached = case.time_reached
    if case.completed:
        return figures.StabilityCell(1.0, "done")
    if case.status == "lost":
        # It reached the end time, but its solution was gone from the health verdict's time on.
        lost_at = float(case.attribute("health_time"))
        fraction = lost_at / case.end_time if case.end_time > 0 else float("nan")
        return figures.StabilityCell(min(max(fraction, 0.0), 1.0), f"{reached:.3g} s\nlost at\n{lost_at:.3g} s",
                                     stopped=True)
    fraction = reached / case.end_time if case.end_time > 0 else float("nan")
    reason = textwrap.fill(case.failure_reason or case.status, 9)
    return figures.StabilityCell(min(max(fraction, 0.0), 1.0), f"{reached:.3g} s\n{reason}", stopped=True)


def stability_figure(study, all_series, directory):
    refine = all_series[0].refine
    columns = sorted({c.keys[refine] for s in all_series for c in s.cases}, key=_sort_value)
    panels = {}
    for series in all_series:
        method, problem = split_label(series)
        panel = panels.setdefault(problem, figures.StabilityPanel(problem, columns, [], {}))
        row = method or series.label
        panel.rows.append(row)
        for case in series.cases:
            panel.cells[(row, case.keys[refine])] = stability_cell(case)
    end = series_end_time(all_series[0])
    figure = figures.stability_map(list(panels.values()), f"{study}: time reached [s] of end time {end:g} s and "
                                   f"why a run stopped", refine)
    path = directory / f"{slug(study, 'stability')}.png"
    figures.save_png(figure, path)
    return FigureEntry(study, path, f"{study}: how far each case got (cf. table 3.2 of 000_1dbcb8acb6dddab9.txt): "
                                    f"time reached and failure reason (done: reached the end time); hatched: stopped before the end time, "
                                    f"or lost its solution (the time it was lost shown and coloured); "
                                    f"grey: no results (status shown).")


def _sort_value(value):
    return (0, value, "") if isinstance(value, (int, float)) else (1, 0, str(value))


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


def profile_figure(study, all_series, directory):
    panels, line = [], None
    for series in all_series:
        case = finest_completed(series)
        lines = read_probe_lines(case.results_path) if case else []
        if not lines or lines[0].time.size == 0:
            continue
        line = lines[0]
        panels.append(figures.ProfilePanel(f"{series.label}\n{case.keys[series.refine]} {series.refine}",
                                           line.positions, profile_snapshots(line)))
    if not panels:
        return None
    unit = norms.QUANTITY_UNITS.get(line.quantity, "")
    label = norms.QUANTITY_LABELS.get(line.quantity, line.quantity)
    figure = figures.profiles(panels, f"{study}: {label} along probe line {line.name}",
                              PARAMETER_LABELS.get(line.parameter, line.parameter), f"{label} [{unit}]", unit)
    path = directory / f"{slug(study, 'profile', line.name)}.png"
    figures.save_png(figure, path)
    return FigureEntry(study, path, f"{study}: simulated (markers) and exact (lines) {label} along probe line "
                                    f"{line.name} at the last output and where the exact profile is largest, finest "
                                    f"completed case of each series; below: simulated - exact.")


def history_figure(study, all_series, directory):
    panels, history = [], None
    for series in all_series:
        case = finest_completed(series)
        found = read_point_history(case.results_path) if case else None
        if found is None or found.time.size == 0:
            continue
        history = found
        where = ", ".join(f"{x:.3g}" for x in np.ravel(history.reference_position))
        panels.append(figures.ProfilePanel(f"{series.label}\n{case.keys[series.refine]} {series.refine}, "
                                           f"point ({where}) m", history.time,
                                           [figures.Snapshot("", history.simulated, history.exact)]))
    if not panels:
        return None
    unit = norms.QUANTITY_UNITS.get(history.quantity, "")
    label = norms.QUANTITY_LABELS.get(history.quantity, history.quantity)
    figure = figures.profiles(panels, f"{study}: {label} at material point {history.name} over time",
                              "time t [s]", f"{label} [{unit}]", unit, markers=False)
    path = directory / f"{slug(study, 'history', history.name)}.png"
    figures.save_png(figure, path)
    return FigureEntry(study, path, f"{study}: {label} at material point {history.name} after every step, finest "
                                    f"completed case of each series, against the exact motion; below: "
                                    f"simulated - exact.")


def spectrum_figure(study, all_series, styles, directory):
    panels, quantity = {}, ""
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
    if not panels:
        return None
    unit = norms.QUANTITY_UNITS.get(quantity, "")
    label = norms.QUANTITY_LABELS.get(quantity, quantity)
    figure = figures.error_spectra(list(panels.items()), f"{study}: angular spectrum of the {label} error on the "
                                   f"material circle at the last output", f"amplitude of mode m [{unit}]")
    path = directory / f"{slug(study, 'spectrum')}.png"
    figures.save_png(figure, path)
    return FigureEntry(study, path, f"{study}: amplitude of angular mode m of the {label} error around the material "
                                    f"circle (/probes/circle/error_spectrum) at the last output, finest case of each "
                                    f"series that has one; the exact motion is axisymmetric, so m > 0 is lost "
                                    f"axisymmetry.")


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
    figure = figures.pressure_profiles(panels, f"{study}: contact pressure at {when}", "distance x from the axis [mm]",
                                       "contact pressure [MPa]")
    path = directory / f"{slug(study, 'contact-pressure')}.png"
    figures.save_png(figure, path)
    refine = found[0][0].refine
    return FigureEntry(study, path, f"{study}: contact pressure on the plate [MPa] against distance x from the axis "
                                    f"[mm] at {when} (/probes/contact_pressure); markers: simulated at the cell "
                                    f"midpoints, one series per {refine} level; line: the exact (Hertz) pressure "
                                    f"p0 sqrt(1 - x^2/a^2) at the load the finest case measured, dotted at its "
                                    f"half-width a; x up to twice the largest x where that exact pressure is "
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
    path = directory / f"{slug(study, 'load-approach')}.png"
    figures.save_png(figure, path)
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
        curves.append(figures.HealthCurve(label, monitors.time, relative_energy_created(monitors),
                                          monitors.column("min_J"), monitors.column("max_J"),
                                          monitors.column("max_speed_over_wave_speed"),
                                          monitors.column("max_domain_distortion"), style, stop,
                                          monitors.column("cfl_step") / monitors.column("stable_step"),
                                          monitors.column("max_wave_speed_ratio"),
                                          monitors.column("max_basis_stiffening")))
    figure = figures.run_health(curves, f"{study}: run health at the output times")
    path = directory / f"{slug(study, 'health')}.png"
    figures.save_png(figure, path)
    caption = (f"{study}: the run's health at each output time (/probes/monitors), one line per case. From the top: "
               "the energy balance error, abs(energy_created) over energy_scale, the solver's scale of its blow-up "
               "and health tests (the larger of the initial energy and the largest abs(work) any one work_* term "
               "has done by then; log scale; absent from results files written before it); "
               "min J and max J over the particles (the lower and upper line of a case's colour), dotted at J = 0; "
               "the largest particle speed over its wave speed; the largest CPDI domain distortion (1: a square "
               "domain; log scale; none for linear MPM); where the results files have them, what lifts the signal "
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


def study_figures(suite, study, rows, directory):
    cases = suite.cases_of(study)
    all_series = study_series(suite, study)
    if not all_series:
        return []
    styles = series_styles(all_series)
    quantities = line_quantities(cases)
    pairs = figure_norms(suite, study, cases)
    entries = []

    def add(make, *args):
        # A results file damaged where a figure reads it (a missing or
        # misshapen probe dataset) costs that figure, named with the cause, and
        # the rest of the report renders.
        try:
            entries.append(make(*args))
        except (OSError, KeyError, ValueError, TypeError, IndexError) as error:
            entries.append(FigureEntry(study, None, f"{study}: {make.__name__.replace('_', ' ')} left out: a results "
                                                    f"file could not be read for it ({type(error).__name__}: {error})"))

    for norm, t in pairs:
        add(error_figure, study, norm, t, rows, styles, quantities, directory)
    if pairs:
        norm = pairs[0][0]
        add(work_precision_figure, study, all_series, norm, norms.norm_unit(norm, quantities), styles, directory)
    add(stability_figure, study, all_series, directory)
    add(health_figure, study, all_series, directory)
    add(profile_figure, study, all_series, directory)
    add(history_figure, study, all_series, directory)
    add(contact_pressure_figure, study, all_series, directory)
    add(load_approach_figure, study, all_series, directory)
    add(spectrum_figure, study, all_series, styles, directory)
    return [e for e in entries if e is not None]


# ---------------------------------------------------------------- tables


@dataclass(frozen=True)
class Table:
    headers: list
    rows: list                   # lists of strings
    css: list = None             # optional CSS class per row
    kind: str = ""               # optional CSS class of the table


def number(value, spec=".3g"):
    return "-" if value is None or not math.isfinite(value) else format(value, spec)


def case_table(suite):
    rows, css = [], []
    for c in suite.cases:
        reached = f"{number(c.time_reached)} / {number(c.end_time)}"
        rows.append([c.id, c.status, reached, "" if c.completed else c.failure_reason, number(c.wall_time_s),
                     number(c.attribute("steps"), "g"), number(c.attribute("particle_count"), "g")])
        css.append(c.status)
    return Table(["case", "status", "reached / end time [s]", "failure reason", "wall time [s]", "steps",
                  "particles"], rows, css)


def measurement_text(value):
    """4 significant digits for numbers (nan shown as such), text as it is."""
    if isinstance(value, (bool, np.bool_)):
        return str(value)
    if isinstance(value, (int, float, np.number)):
        return format(float(value), ".4g")
    if isinstance(value, np.ndarray):
        return ", ".join(measurement_text(v) for v in value.ravel())
    return str(value)


def measurement_table(cases):
    """Rows = the cases, columns = every /measurements attribute they have (first-seen
    order); None when no case has one."""
    names = list(dict.fromkeys(n for c in cases if c.results for n in c.results.measurements))
    if not names:
        return None
    rows = []
    for c in cases:
        measured = c.results.measurements if c.results else {}
        rows.append([c.id] + [measurement_text(measured[n]) if n in measured else "-" for n in names])
    return Table(["case"] + names, rows, kind="measurements")


def measurement_sections(suite):
    sections = []
    for study in suite.study_names():
        table = measurement_table(suite.cases_of(study))
        if table is not None:
            sections.append((f"Measurements: {study}", f"The /measurements attributes of each case of study {study} "
                             "(4 significant digits; - where a case has none): what the scene measures at the end "
                             "of the run; an attribute ending in _exact is the exact value of the one without the "
                             "suffix, one ending in _error its relative error (reports/results-format.md).", table))
    return sections


def reference_sections(suite, rows):
    """One section per [[reference]] table: the published numbers beside this suite's
    (reports/references.py)."""
    try:
        tables = references.read_references(suite.references)
    except references.ReferenceError as error:
        return [("Against published results", f"Not shown: {error}", None)]
    sections = []
    for reference in tables:
        if reference.quantity == "time_reached":
            headers, cells, css = references.time_reached_table(suite, reference)
            text = (f"Time reached [s] in {reference.source}, beside the time each case of this suite reached "
                    "(with the reason when it stopped before its end time; pending: not run yet).")
            sections.append(("Against published results: time reached", text, Table(headers, cells, css)))
        elif reference.quantity == "error":
            quantities = line_quantities(suite.cases_of(reference.studies[0]))
            unit = norms.norm_unit(reference.norm, quantities)
            time = f"t = {reference.time:g} s" if math.isfinite(reference.time) else "the end time"
            headers, cells, css = references.error_table(suite, reference, lookup_error, unit)
            text = (f"{reference.norm} ({norms.describe_norm(reference.norm, quantities)}) at {time} in {reference.source}, "
                    "beside the same norm of each case of this suite that matches the row.")
            sections.append((f"Against published results: {reference.norm}", text, Table(headers, cells, css)))
        else:
            def unit_of(study):
                return norms.norm_unit(reference.norm, line_quantities(suite.cases_of(study)))
            matched = references.order_rows(suite, reference, lambda study: study_series(suite, study), order_row,
                                            unit_of)
            body = [[str(v) for v in values] + [f"{published:g}", f"{row.study}: {row.series.label}"]
                    + order_cells(row)[3:] for values, published, row in matched]
            headers = list(reference.columns) + ["reference order", "series", "t [s]", "levels", "finest error",
                                                 "pairwise orders", "least-squares order [95% CI]", "class"]
            text = (f"Observed order of {reference.norm} in {reference.source}, beside the order of each refinement "
                    "series of this suite whose cases match the row (definitions under Observed orders).")
            sections.append((f"Against published results: observed order of {reference.norm}", text,
                             Table(headers, body, [r.classification.split()[0] for _, _, r in matched])))
    return sections


def order_cells(row):
    fit = row.fit
    ci = f" [{fit.ci_low:.2f}, {fit.ci_high:.2f}]" if math.isfinite(fit.ci_low) else ""
    finest = row.levels[-1] if row.levels else None
    shown = row.has_order and math.isfinite(fit.order)
    return [row.study, row.series.label, f"{row.norm} [{row.unit}]", f"{row.time:g}",
            ", ".join(str(l.value) for l in row.levels) or "-",
            number(finest.error) if finest else "-",
            (", ".join(number(p, ".2f") for p in row.pairwise) if row.has_order else "") or "-",
            (number(fit.order, ".3f") + ci) if shown else "-",
            row.classification if row.has_order else floor_text(row.series.refine, row.roundoff)]


def orders_table(rows):
    return Table(["study", "series", "norm", "t [s]", "levels", "finest error", "pairwise orders",
                  "least-squares order [95% CI]", "class"], [order_cells(r) for r in rows],
                 [r.classification.split()[0] for r in rows])


def gci_table(rows):
    cells = []
    for r in rows:
        g = r.convergence
        band = abs(r.values[-1]) * g.gci_fine
        error = abs(r.values[-1] - r.exact)
        cells.append([r.study, r.series.label, f"{r.probe} {r.quantity}", f"{r.time:g}",
                      ", ".join(str(v) for v in r.levels), ", ".join(number(v, ".6g") for v in r.values),
                      number(g.observed_order, ".2f"), g.convergence, number(g.extrapolated, ".6g"),
                      number(100 * g.gci_fine, ".3g"), number(g.asymptotic_ratio, ".3f"),
                      number(r.exact, ".6g"),
                      "-" if g.convergence == "round-off" else "yes" if error <= band else "no"])
    return Table(["study", "series", "quantity", "t [s]", "levels", "values (coarse to fine)", "observed p",
                  "convergence", "extrapolated", "GCI fine [%]", "asymptotic ratio", "exact (check)",
                  "exact within GCI band"], cells)


def expectation_table(verdicts):
    return Table(gate.HEADER, [gate.verdict_row(v) for v in verdicts],
                 ["PASS" if v.passed else "FAIL" for v in verdicts])


def _joined(values):
    return ";".join(repr(float(v)) for v in values)


def _per_level(row, value):
    """value(check) for each usable level of the row, NaN where its exact signal is not known
    (and for a row of fewer than two levels, which is not checked)."""
    if len(row.roundoff) != len(row.levels):
        return [float("nan")] * len(row.levels)
    return [float("nan") if c is None else value(c) for c in row.roundoff]


def write_orders_csv(rows, path):
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow([name for name, _ in ORDERS_CSV_COLUMNS])
        for r in rows:
            finest = r.levels[-1] if r.levels else None
            writer.writerow([r.study, r.series.label, r.norm, r.unit, repr(r.time), r.series.refine,
                             ";".join(str(l.value) for l in r.levels), _joined(l.h for l in r.levels),
                             _joined(l.error for l in r.levels), _joined(r.pairwise) if r.has_order else "",
                             *(repr(v if r.has_order else float("nan")) for v in (r.fit.order, r.fit.ci_low,
                                                                                   r.fit.ci_high)),
                             r.classification, finest.value if finest else "", repr(finest.h) if finest else "",
                             repr(finest.error) if finest else "",
                             ";".join(f"{l.value}: {l.reason}" for l in r.left_out),
                             _joined(_per_level(r, lambda c: c.relative_error)),
                             _joined(_per_level(r, lambda c: c.relative_floor)),
                             _joined(_per_level(r, lambda c: c.relative_settling))])


def write_gci_csv(rows, path):
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["study", "series", "probe", "quantity", "time", "levels", "f_coarse", "f_medium", "f_fine",
                         "ratio", "observed_order", "convergence", "extrapolated", "gci_fine", "gci_medium",
                         "asymptotic_ratio", "exact"])
        for r in rows:
            g = r.convergence
            writer.writerow([r.study, r.series.label, r.probe, r.quantity, repr(r.time),
                             ";".join(str(v) for v in r.levels), *map(repr, r.values), repr(r.ratio),
                             repr(g.observed_order), g.convergence, repr(g.extrapolated), repr(g.gci_fine),
                             repr(g.gci_medium), repr(g.asymptotic_ratio), repr(r.exact)])


# ---------------------------------------------------------------- documents


@dataclass(frozen=True)
class Report:
    suite: object
    generated: datetime
    status_counts: dict
    norm_check: tuple
    order_rows: list
    gci_rows: list
    sections: list               # (title, paragraph, Table or None)
    figures: list                # FigureEntry


def status_counts(suite):
    counts = {}
    for case in suite.cases:
        counts[case.status] = counts.get(case.status, 0) + 1
    return counts


DEFINITIONS = (
    "Norms: L1_<line> is eq. 3.1 of 000_1dbcb8acb6dddab9.txt, the mean over a probe line's material points of "
    "|q_sim - q_exact|; particle_L1, particle_L2 and particle_Linf are the reference-volume-weighted mean, RMS and "
    "maximum of the particle displacement error |x_p - x_exact(X_p, t)|; particle_relative_L2_integrated is "
    "sqrt(int sum V_p0 e_p^2 dt / int sum V_p0 |x_exact - X_p|^2 dt) from t = 0 (reports/norms.py). Orders: pairwise "
    "p = ln(E_i/E_i+1)/ln(h_i/h_i+1) between consecutive usable levels; least-squares slope of ln E against ln h with "
    "a 95% Student-t interval (none with two levels). Class: round-off when some level's error is positive and at "
    f"most its round-off floor, ({orders.ROUNDOFF_ULPS} + steps) ulps of the numbers the error is a difference of "
    "(the body's coordinates for a displacement, not the displacement; 1 for a relative error): rounding alone "
    "can explain it, and no order is given (the error over the exact signal it measures is shown); settling when "
    "the run settles to a static state and some level's error is positive and at most what its stopping short of "
    "that state could leave in the norm (the results file's /settling, reports/README.md): no order is given "
    "either; stalled when "
    f"the finest pairwise order is below {orders.STALLED_BELOW}; non-asymptotic when the pairwise orders span more "
    f"than {orders.ASYMPTOTIC_SPREAD}; unchecked with one pair; asymptotic otherwise. A level is usable when its "
    "case wrote the norm at that time (a failed run keeps the outputs it reached).")


def build_report(suite, figure_directory):
    rows, grid_rows = order_rows(suite), gci_rows(suite)
    sections = [("Cases", "Status from manifest.json; time reached, failure reason, wall time of the time loop, "
                 "steps and particle count from each results file.", case_table(suite))]
    if suite.expectations:
        try:
            verdicts = gate.gate(suite)
            summary = gate.summary_line(verdicts, len(suite.expectations))
            sections.append(("Expectations", f"As checked by mpmvv gate: {summary}.", expectation_table(verdicts)))
        except SuiteDirectoryError as error:
            sections.append(("Expectations", f"Not checked: {error}", None))
    sections += reference_sections(suite, rows)
    sections += measurement_sections(suite)
    fitted = [r for r in rows if len(r.levels) >= 2]
    sections.append(("Observed orders", DEFINITIONS + f" {len(rows) - len(fitted)} of {len(rows)} (series, norm, "
                     "time) combinations have fewer than two usable levels and are left out here. orders.csv has "
                     "every row, with the columns " + "; ".join(f"{n} ({m})" for n, m in ORDERS_CSV_COLUMNS) + ".",
                     orders_table(fitted)))
    sections.append(("Richardson extrapolation and grid convergence index",
                     "Roache's GCI (safety factor 1.25) of the point probe's simulated value on the three finest "
                     "completed levels of each series with a constant refinement ratio, at the output time where the "
                     "finest value is largest in magnitude, treated as a quantity without an exact value; the exact "
                     "value is shown only to check the band f_fine (1 +- GCI). Convergence round-off: a change between "
                     f"two levels is at most ({orders.ROUNDOFF_ULPS} + steps) ulps of the point's |X| (pi for an "
                     "angle), which rounding alone can explain: no order, extrapolation or GCI.", gci_table(grid_rows)))
    entries = [e for study in suite.study_names() for e in study_figures(suite, study, rows, figure_directory)]
    return Report(suite, datetime.now(), status_counts(suite), stored_norm_check(suite), rows, grid_rows,
                  sections, entries)


def header_lines(report):
    suite = report.suite
    counts = ", ".join(f"{n} {s}" for s, n in report.status_counts.items())
    checked, largest = report.norm_check
    return [
        suite.description or "(no description in suite.toml)",
        f"Directory {suite.directory}; manifest written {suite.written:%Y-%m-%d %H:%M}; report generated "
        f"{report.generated:%Y-%m-%d %H:%M}.",
        f"{len(suite.cases)} cases: {counts}.",
        f"Eq. 3.1 recomputed from the probe arrays of {checked} results files agrees with the stored L1 columns to "
        f"{largest:.1e} (relative).",
    ]


CSS = """
body { font-family: sans-serif; margin: 1.5em auto; max-width: 1400px; color: #222; }
table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: left; vertical-align: top; }
th { background: #f0f0f0; position: sticky; top: 0; }
tr.completed td:nth-child(2), tr.PASS td:nth-child(10), tr.asymptotic td:last-child { color: #1a7f37; }
tr.failed td:nth-child(2), tr.lost td:nth-child(2), tr.crashed td:nth-child(2), tr.timeout td:nth-child(2), tr.error td:nth-child(2),
tr.FAIL td:nth-child(10), tr.stalled td:last-child { color: #c62828; font-weight: bold; }
tr.pending td:nth-child(2), tr.non-asymptotic td:last-child { color: #9a6700; }
figure { margin: 1em 0 2em; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { font-size: 0.9em; color: #444; }
table.measurements td + td { white-space: nowrap; }
"""


def html_table(table):
    # a header may break after an underscore (long /measurements names)
    head = "".join(f"<th>{html.escape(h).replace('_', '_<wbr>')}</th>" for h in table.headers)
    body = []
    for index, row in enumerate(table.rows):
        css = f' class="{html.escape(table.css[index])}"' if table.css else ""
        body.append(f"<tr{css}>" + "".join(f"<td>{html.escape(cell)}</td>" for cell in row) + "</tr>")
    kind = f" class='{html.escape(table.kind)}'" if table.kind else ""
    return f"<table{kind}><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def render_html(report):
    suite = report.suite
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(suite.name)}</title>"
             f"<style>{CSS}</style></head><body><h1>Convergence report: {html.escape(suite.name)}</h1>"]
    parts += [f"<p>{html.escape(line)}</p>" for line in header_lines(report)]
    for title, text, table in report.sections:
        parts.append(f"<h2>{html.escape(title)}</h2><p>{html.escape(text)}</p>")
        parts.append(html_table(table) if table and table.rows else "<p><em>none</em></p>")
    parts.append("<h2>Figures</h2>")
    for study in dict.fromkeys(e.study for e in report.figures):
        parts.append(f"<h3>{html.escape(study)}</h3>")
        for entry in (e for e in report.figures if e.study == study):
            if entry.path is None:
                parts.append(f"<p class='left-out'><em>{html.escape(entry.caption)}</em></p>")
                continue
            data = base64.b64encode(entry.path.read_bytes()).decode()
            parts.append(f"<figure><img alt='{html.escape(entry.path.name)}' src='data:image/png;base64,{data}'>"
                         f"<figcaption>{html.escape(entry.caption)}</figcaption></figure>")
    parts.append("</body></html>")
    return "\n".join(parts)


def markdown_table(table):
    escape = lambda cell: cell.replace("|", "\\|").replace("\n", " ")  # noqa: E731
    lines = ["| " + " | ".join(table.headers) + " |", "|" + "---|" * len(table.headers)]
    lines += ["| " + " | ".join(escape(cell) for cell in row) + " |" for row in table.rows]
    return "\n".join(lines)


def render_markdown(report, output_directory):
    lines = [f"# Convergence report: {report.suite.name}", ""]
    lines += [line + "\n" for line in header_lines(report)]
    for title, text, table in report.sections:
        lines += [f"## {title}", "", text, "", markdown_table(table) if table and table.rows else "_none_", ""]
    lines += ["## Figures", ""]
    for study in dict.fromkeys(e.study for e in report.figures):
        lines += [f"### {study}", ""]
        for entry in (e for e in report.figures if e.study == study):
            if entry.path is None:
                lines += [f"_{entry.caption}_", ""]
                continue
            lines += [f"![{entry.caption}]({entry.path.relative_to(output_directory).as_posix()})", "",
                      f"_{entry.caption}_", ""]
    return "\n".join(lines)


def write_report(directory, output=None):
    """Read the suite, write every output; returns the paths written."""
    suite = read_suite(directory)
    output = Path(output) if output else suite.directory / "report"
    figure_directory = output / "figures"
    figure_directory.mkdir(parents=True, exist_ok=True)
    for old in figure_directory.glob("*.png"):
        old.unlink()
    report = build_report(suite, figure_directory)
    written = {"html": output / "report.html", "markdown": output / "report.md",
               "orders": output / "orders.csv", "gci": output / "gci.csv"}
    written["html"].write_text(render_html(report))
    written["markdown"].write_text(render_markdown(report, output))
    write_orders_csv(report.order_rows, written["orders"])
    write_gci_csv(report.gci_rows, written["gci"])
    return written, sum(e.path is not None for e in report.figures)


class _OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"mpmvv report: {message} (see --help)\n")


def main(argv):
    parser = _OneLineParser(prog="mpmvv report", description="Tables, figures and report.html of a suite output "
                            "directory, from its results files only.")
    parser.add_argument("directory", metavar="DIR", help="a suite output directory (mpmvv suite SUITE -o DIR)")
    parser.add_argument("-o", "--output", metavar="OUT", help="where to write (default DIR/report)")
    args = parser.parse_args(argv)
    start = clock.perf_counter()
    try:
        written, figure_count = write_report(args.directory, args.output)
    except SuiteDirectoryError as error:
        print(f"mpmvv report: {error}", file=sys.stderr)
        return 2
    except OSError as error:
        # A directory it cannot write (read-only, full): one line, not a traceback.
        where = args.output or str(Path(args.directory) / "report")
        print(f"mpmvv report: cannot write the report to {where}: {error.strerror or error} "
              f"({error.filename or where}); choose another place with -o", file=sys.stderr)
        return 2
    for path in written.values():
        print(f"wrote {path}")
    print(f"{figure_count} figures in {written['html'].parent / 'figures'}; "
          f"{clock.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
