"""The figures of every study of a report (report.py): error against h,
error against run time, the stability map, and study_figures, which adds the
scene-specific ones (scene_figures.py) where the results files hold their data."""
import math
import textwrap

from . import figures
from . import norms
from .figure_parts import FigureEntry, saved, sort_value, split_label, time_text
from .report_rows import error_columns, line_quantities, series_end_time, study_series
from .results import lookup_error
from .ring_figures import l1_over_time_figure, marker_refinement_figure, particle_map_figure
from .scene_figures import (contact_pressure_figure, health_figure, history_figure, load_approach_figure, profile_figure,
                           spectrum_figure)
from .series import floor_text, size_name


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
    path = saved(figure, directory, study, 'error', norm, 'end' if time is None else time)
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


def work_points(series, norm):
    """(wall time, error at the end time) of the series' completed cases."""
    return [(c.wall_time_s, lookup_error(c, norm, c.end_time)[0]) for c in series.cases if c.completed]


def work_precision_figure(study, all_series, norm, unit, styles, directory):
    panels = {}
    for series in all_series:
        method, problem = split_label(series)
        points = work_points(series, norm)
        curve = figures.Curve(method or series.label, [p[0] for p in points], [p[1] for p in points],
                              styles[series.label])
        panels.setdefault(problem, []).append(curve)
    end = series_end_time(all_series[0])
    figure = figures.work_precision(list(panels.items()), f"{study}: work against precision, {norm} at the end "
                                    f"time", f"{norm} at t = {end:g} s [{unit}]")
    path = saved(figure, directory, study, 'work-precision')
    return FigureEntry(study, path, f"{study}: {norm} at the end time against wall time of the time loop for the "
                                    f"completed cases, one curve per method setting across "
                                    f"{all_series[0].refine}; circled: Pareto front (no case is both faster and "
                                    f"more accurate).")


def external_comparison_figure(suite, directory):
    """Every study of the suite in one work-precision figure when one of them is run by
    another program (external_command): that program's error at equal run time beside
    mpmvv's own studies. None for a suite without such a study, or with it alone."""
    studies = suite.study_names()
    external = [s for s in studies if any(c.keys.get("external_command") for c in suite.cases_of(s))]
    if not external or len(studies) < 2:
        return None
    pairs = figure_norms(suite, external[0], suite.cases_of(external[0]))
    if not pairs:
        return None
    norm = pairs[0][0]
    curves = []
    for k, study in enumerate(studies):
        for m, series in enumerate(study_series(suite, study)):
            points = work_points(series, norm)
            style = figures.Style(figures.COLOURS[k % len(figures.COLOURS)], figures.MARKERS[m % len(figures.MARKERS)])
            curves.append(figures.Curve(f"{study} ({series.label})", [p[0] for p in points], [p[1] for p in points],
                                        style))
    quantities = line_quantities(suite.cases)
    figure = figures.work_precision([("every study", curves)], f"work against precision across the studies, {norm} "
                                    "at the end time", f"{norm} [{norms.norm_unit(norm, quantities)}]")
    path = saved(figure, directory, "suite", "work-precision")
    return FigureEntry("all studies", path,
                       f"{norm} at the end time against wall time for the completed cases of every study, one curve "
                       f"per study and series (each across its refinement), the external program's "
                       f"({', '.join(external)}: its own wall time as mpmvv measured it around the program) beside "
                       f"the others; circled: Pareto front (no case is both faster and more accurate).")


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
    columns = sorted({c.keys[refine] for s in all_series for c in s.cases}, key=sort_value)
    panels = {}
    for series in all_series:
        method, problem = split_label(series)
        panel = panels.setdefault(problem, figures.StabilityPanel(problem, columns, [], {}))
        row = method or series.label
        panel.rows.append(row)
        for case in series.cases:
            panel.cells[(row, case.keys[refine])] = stability_cell(case)
    end = series_end_time(all_series[0])
    cells = [cell for panel in panels.values() for cell in panel.cells.values()]
    if cells and all(cell.fraction == 1.0 and not cell.stopped for cell in cells):
        # A map of one colour says less than a sentence.
        return FigureEntry(study, None, f"{study}: every one of its {len(cells)} cases reached the end time "
                                        f"{end:g} s with its solution kept (no stability map drawn).")
    figure = figures.stability_map(list(panels.values()), f"{study}: time reached [s] of end time {end:g} s and "
                                   f"why a run stopped", refine)
    path = saved(figure, directory, study, 'stability')
    return FigureEntry(study, path, f"{study}: how far each case got (cf. table 3.2 of 000_1dbcb8acb6dddab9.txt): "
                                    f"time reached and failure reason (done: reached the end time); hatched: stopped before the end time, "
                                    f"or lost its solution (the time it was lost shown and coloured); "
                                    f"grey: no results (status shown).")


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
        add(marker_refinement_figure, study, suite, norm, pairs[0][1], quantities, directory)
    add(l1_over_time_figure, study, all_series, quantities, directory)
    add(particle_map_figure, study, all_series, directory)
    add(stability_figure, study, all_series, directory)
    add(health_figure, study, all_series, directory)
    add(profile_figure, study, all_series, directory)
    add(history_figure, study, all_series, directory)
    add(contact_pressure_figure, study, all_series, directory)
    add(load_approach_figure, study, all_series, directory)
    add(spectrum_figure, study, all_series, styles, directory)
    return [e for e in entries if e is not None]
