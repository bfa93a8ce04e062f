"""Figures in the manner of the Sandia report's ring study
(000_1dbcb8acb6dddab9.txt): the L1 error of each probe line over time, one
curve per mesh (its figures 3.6, 3.8 and 3.9), and the marker refinement at a
fixed mesh, the error against particles per direction with one curve per cell
count (its figure 3.6(b): "no convergence ... as we increase the number of
markers per linear direction"), and maps of the particles at chosen times
coloured by speed and by their error (its figures 3.1, 3.2, 3.7, 3.10). Drawn
wherever the results files hold the data: L1_<line> columns at three or more
output times, a study that sweeps both cells and particles_per_direction, or
particle snapshots (particle_fields = "outputs")."""
import numpy as np

from . import figures
from . import norms
from .figure_parts import FigureEntry, saved, sort_value
from .results import lookup_error, read_snapshot, read_snapshot_times

LARGEST_CURVES = 12    # more cases than this: each series' coarsest and finest with results
LINES_DRAWN = 4


def _curve_cases(all_series):
    """Every case with results, when some case has three or more output times (a
    failed run's curve is as short as the outputs it made)."""
    chosen = [(s, c) for s in all_series for c in s.cases if c.results is not None and c.results.error_times.size]
    if not any(c.results.error_times.size >= 3 for _, c in chosen):
        return []
    if len(chosen) <= LARGEST_CURVES:
        return chosen
    picked = []
    for series in all_series:
        own = [c for s, c in chosen if s is series]
        picked += [(series, c) for c in dict.fromkeys(own[:1] + own[-1:])]
    return picked


def _case_label(series, case):
    label = f"{series.label}, {series.refine}={case.keys[series.refine]}"
    if case.status == "lost":
        return label + f" (lost at t = {float(case.attribute('health_time')):.3g} s)"
    return label if case.completed else label + f" ({case.status} at t = {case.time_reached:.3g} s)"


def l1_over_time_figure(study, all_series, quantities, directory):
    chosen = _curve_cases(all_series)
    lines = [n for n in dict.fromkeys(n for _, c in chosen for n in c.results.errors) if n.startswith("L1_")]
    if not chosen or not lines:
        return None
    panels = []
    for line in lines[:LINES_DRAWN]:
        curves = []
        for series, case in chosen:
            if line not in case.results.errors:
                continue
            # Colour: the series (its own, not its method's: two amplitudes of one
            # method must not look alike); marker: the level.
            level = list(series.cases).index(case)
            style = figures.Style(figures.COLOURS[all_series.index(series) % len(figures.COLOURS)],
                                  figures.MARKERS[level % len(figures.MARKERS)])
            # lookup_error's rule: no value from the time the solution was found lost.
            times = case.results.error_times
            curves.append(figures.Curve(_case_label(series, case), times,
                                        [lookup_error(case, line, t)[0] for t in times], style))
        panels.append(figures.LinePanel(line, curves))
    unit = norms.norm_unit(lines[0], quantities)
    figure = figures.log_curves(panels, f"{study}: L1 of each probe line over time", "time t [s]",
                                f"L1 [{unit}]")
    path = saved(figure, directory, study, 'L1-over-time')
    left = " (" + ", ".join(lines[LINES_DRAWN:]) + " not drawn)" if len(lines) > LINES_DRAWN else ""
    silent = [_case_label(s, c) for s in all_series for c in s.cases
              if c.results is not None and not c.results.error_times.size]
    silent = f" No output before it stopped, so no curve: {'; '.join(silent)}." if silent else ""
    meaning = norms.describe_norm(lines[0], quantities)
    return FigureEntry(study, path, f"{study}: L1 of each probe line{left} at every output time ({lines[0]}: "
                                    f"{meaning}; the others alike), one curve per case "
                                    f"(colour: series, marker: level; with more than {LARGEST_CURVES} cases each "
                                    f"series' coarsest and finest), as figures 3.6, 3.8 and 3.9 of "
                                    f"000_1dbcb8acb6dddab9.txt draw it; a curve ends where its run stopped or its "
                                    f"solution was found lost.{silent}")


def marker_refinement_figure(study, suite, norm, time, quantities, directory):
    varied = suite.varied_keys(study)
    if "cells" not in varied or "particles_per_direction" not in varied:
        return None
    others = [k for k in varied if k not in ("cells", "particles_per_direction")]
    cases = [c for c in suite.cases_of(study) if "cells" in c.keys and "particles_per_direction" in c.keys]
    panels = {}
    for case in cases:
        problem = ", ".join(f"{k}={case.keys[k]}" for k in others if k in case.keys) or study
        panels.setdefault(problem, {}).setdefault(case.keys["cells"], []).append(case)
    drawn, empty = [], []
    for problem, by_cells in panels.items():
        curves = []
        for i, cells in enumerate(sorted(by_cells, key=sort_value)):
            own = sorted(by_cells[cells], key=lambda c: float(c.keys["particles_per_direction"]))
            if len(own) < 2:
                continue
            when = lambda c: c.end_time if time is None else time  # noqa: E731
            curves.append(figures.Curve(f"cells={cells}", [float(c.keys["particles_per_direction"]) for c in own],
                                        [lookup_error(c, norm, when(c))[0] for c in own],
                                        figures.Style(figures.COLOURS[i % len(figures.COLOURS)],
                                                      figures.MARKERS[i % len(figures.MARKERS)])))
        if any(np.isfinite(y) for c in curves for y in c.y):
            drawn.append(figures.LinePanel(problem, curves))
        elif curves:
            empty.append(problem)
    if not drawn:
        return None
    unit = norms.norm_unit(norm, quantities)
    when = "the end time" if time is None else f"t = {time:g} s"
    figure = figures.log_curves(drawn, f"{study}: marker refinement at fixed mesh, {norm} at {when}",
                                "particles per direction", f"{norm} [{unit}]", log_x=True)
    path = saved(figure, directory, study, 'marker-refinement', norm)
    return FigureEntry(study, path, f"{study}: {norms.describe_norm(norm, quantities)} at {when} against particles "
                                    f"per direction, one curve per mesh (cf. figure 3.6(b) of "
                                    f"000_1dbcb8acb6dddab9.txt); a case without a usable value at that time (stopped "
                                    f"or lost) leaves its point out."
                                    + (f" No usable value at all, so no panel: {'; '.join(empty)}." if empty else ""))


MAPS_DRAWN = 4
MAP_PARTICLES = 200_000


def _spread(items, count):
    """At most `count` of the items, evenly spread and including the last."""
    if len(items) <= count:
        return items
    return [items[round(k * (len(items) - 1) / (count - 1))] for k in range(count)]


def particle_map_figure(study, all_series, directory):
    """The particles of the finest completed case with snapshots (particle_fields =
    "outputs"; else the finest with snapshots): speed and displacement error at up
    to four output times."""
    found = [(s, c, t) for s in all_series for c in s.cases if c.results is not None
             for t in [read_snapshot_times(c.results_path)] if t]
    if not found:
        return None

    def finest_completed_first(entry):
        h = entry[1].h
        return entry[1].completed, -h if np.isfinite(h) else -np.inf
    series, case, all_times = max(found, key=finest_completed_first)
    times = _spread(all_times, MAPS_DRAWN)
    maps = []
    for t, name in times:
        snapshot = read_snapshot(case.results_path, name, MAP_PARTICLES)
        error = (None if snapshot.displacement_error is None
                 else np.linalg.norm(snapshot.displacement_error, axis=1))
        maps.append(figures.ParticleMap(f"t = {t:g} s", snapshot.position, np.linalg.norm(snapshot.velocity, axis=1),
                                        error))
    level = f"{series.refine}={case.keys[series.refine]}"
    figure = figures.particle_maps(maps, f"{study}: particles of {series.label}, {level}", "speed |v| [m/s]",
                                   "displacement error |x - x_exact| [m]")
    path = saved(figure, directory, study, 'particle-maps')
    stopped = "" if case.completed else f" (this run {case.status} at t = {case.time_reached:.3g} s)"
    return FigureEntry(study, path, f"{study}: the particles of {series.label}, {level}{stopped}, at their current "
                                    f"positions at {len(maps)} of its output times, coloured by speed (top, as "
                                    f"figures 3.7 and 3.10 of 000_1dbcb8acb6dddab9.txt) and by the magnitude of "
                                    f"their displacement error (bottom), each row on one scale from 0 to its largest "
                                    f"value (at most {MAP_PARTICLES} particles drawn, every k-th).")
