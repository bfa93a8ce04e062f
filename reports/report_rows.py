"""The numbers of a report (report.py): orders.csv and gci.csv rows, one per
(study, refinement series, norm, output time) and per point-probe series, and
the stored-norm check; the columns of orders.csv and levels.csv are ORDERS_CSV_COLUMNS and
LEVELS_CSV_COLUMNS."""
import math
from dataclasses import dataclass

import numpy as np

from . import norms
from . import orders
from .probes import read_point_history, read_probe_lines
from .series import (DEFAULT_REFINE_KEY, case_roundoff_floor, floor_kind, refined_size, refinement_series,
                     roundoff_checks, series_levels, usable)


# orders.csv: one row per (study, refinement series, norm, time), one value
# per cell; the levels behind each row are levels.csv's (LEVELS_CSV_COLUMNS).
ORDERS_CSV_COLUMNS = (
    ("study", "the study"),
    ("series", "the keys that name the refinement series"),
    ("norm", "an /errors column"),
    ("unit", "its unit"),
    ("time", "output time [s]"),
    ("refine", "the key that refines"),
    ("levels", "how many levels are usable (levels.csv lists them)"),
    ("left_out", "how many levels have no usable value at that time (levels.csv says why)"),
    ("ls_order", "least-squares order (NaN at round-off)"),
    ("ci_low", "lower end of its 95% Student-t interval (NaN with two levels or at round-off)"),
    ("ci_high", "upper end"),
    ("classification", "round-off, settling, asymptotic, non-asymptotic, stalled, unchecked (2 levels) or too few levels"),
    ("finest_level", "refine value of the finest usable level"),
    ("finest_h", "its size (as h)"),
    ("finest_error", "its error"),
)
# levels.csv: one row per level of each orders.csv row, the usable ones coarse
# first, then those left out.
LEVELS_CSV_COLUMNS = (
    ("study", "as orders.csv"), ("series", "as orders.csv"), ("norm", "as orders.csv"), ("unit", "as orders.csv"),
    ("time", "as orders.csv"), ("refine", "as orders.csv"),
    ("level", "the refine key's value"),
    ("h", "the size the refine key sets: cell size h [m]; h / particles_per_direction [m] for particles per "
          "direction; cfl h [m] for cfl; 1 / load_steps (reports/series.py: REFINED_SIZES)"),
    ("error", "the norm at that level (NaN where not usable)"),
    ("used", "1 when the level is usable and in the fit, 0 when left out"),
    ("reason", "why a level is left out; empty when used"),
    ("order_from_coarser", "the order between this usable level and the usable one before it (NaN for the first, "
                           "and at round-off)"),
    ("relative_error", "the error over the exact signal the norm measures at that time (NaN where not known; "
                       "error_* and particle_relative_L2_integrated are relative already: signal 1)"),
    ("roundoff_floor", f"the round-off floor, ({orders.ROUNDOFF_ULPS} + steps) ulps of the numbers the error is a "
                       f"difference of (and {orders.OUTPUT_SPACING_UNITS} spacings of how an external program wrote "
                       "them), over the same signal: a level whose relative_error is at most this is at round-off "
                       "(reports/orders.py)"),
    ("settling", "the settling level over the same signal, the largest error the run's distance from its static "
                 "state at the end could leave (scales.py: settling_scale; NaN for a run that does not settle): a "
                 "level whose relative_error is at most this is at the settling level"),
)
METHOD_KEYS = ("method", "scheme", "particles_per_direction", "cfl", "time_integration", "solver", "load_steps",
               "dilatation", "formulation")
PARAMETER_LABELS = {"reference_radius": "reference radius R [m]", "reference_r": "reference radius R [m]",
                    "reference_x": "reference X [m]", "reference_y": "reference Y [m]",
                    "reference_z": "reference Z [m]", "reference_position": "distance from the origin [m]"}


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
    """The probe lines' quantities of the cases (name -> quantity), with the units
    their results files stored for the /errors columns (.units; norms.norm_unit)."""
    merged = norms.LineQuantities()
    for case in cases:
        if case.results:
            merged.update(case.results.line_quantities)
            merged.units.update(case.results.error_units)
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
    length, pi for an angle, for the worst of the cases: series.case_roundoff_floor): such
    changes measure rounding, and Roache's order of them means nothing."""
    position = np.ravel(np.asarray(history.reference_position, float))
    if history.quantity == "angular_displacement":
        size = math.pi
    elif position.size >= 2 and np.all(np.isfinite(position[:2])):
        size = float(np.hypot(position[0], position[1]))
    else:
        return False
    floor = case_roundoff_floor(cases, size)
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
