"""The tables of a report (report.py): cases, measurements, references,
orders, GCI and expectations, and orders.csv and gci.csv."""
import csv
import io
import math
from dataclasses import dataclass

import numpy as np

from . import gate
from . import norms
from . import references
from .gate_files import write_atomically
from .report_rows import LEVELS_CSV_COLUMNS, ORDERS_CSV_COLUMNS, line_quantities, order_row, study_series
from .results import lookup_error
from .series import floor_text


@dataclass(frozen=True)
class Table:
    headers: list
    rows: list                   # lists of strings
    css: list = None             # optional CSS class per row
    kind: str = ""               # optional CSS class of the table


def number(value, spec=".3g"):
    return "-" if value is None or not math.isfinite(value) else format(value, spec)


def health_cell(case):
    """The case's health verdict, and for a run by another program which of the
    rules could judge it (reports/external-format.md: the J rule needs F, J or
    volumes; the energy balance, the work done on the body, is never known) and
    where its probe lines' tracers came from."""
    health = case.attribute("health", "")
    if not isinstance(health, str) or not health:
        return "-"
    external = case.results.external if case.results is not None else {}
    if not case.keys.get("external_command") or not external:
        return health
    j_rule = str(external.get("J_rule", "")) == "applied"
    judged = "J ratio, norms" if j_rule else "norms"
    unjudged = "energy balance" if j_rule else "energy balance, J ratio (no F, J or volume)"
    tracers = "; tracers placed by mpmvv" if str(external.get("tracers", "")).startswith("interpolated") else ""
    return f"{health} (judged: {judged}; not judged: {unjudged}{tracers})"


def case_table(suite):
    rows, css = [], []
    for c in suite.cases:
        reached = f"{number(c.time_reached)} / {number(c.end_time)}"
        # A case another program ran (external_command): mpmvv does not see its steps.
        steps = "external program" if c.keys.get("external_command") else number(c.attribute("steps"), "g")
        rows.append([c.id, c.status, reached, "" if c.completed else c.failure_reason, health_cell(c),
                     number(c.wall_time_s), steps, number(c.attribute("particle_count"), "g")])
        css.append(c.status)
    return Table(["case", "status", "reached / end time [s]", "failure reason", "health", "wall time [s]", "steps",
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


# What a Measurements section's columns are (the report's glossary).
MEASUREMENTS_DEFINITION = ("the /measurements attributes of each case (4 significant digits; - where a case has "
                           "none): what the scene measures at the end of the run; an attribute ending in _exact is "
                           "the exact value of the one without the suffix, one ending in _error its relative error "
                           "(reports/results-format.md).")


def measurement_sections(suite):
    sections = []
    for study in suite.study_names():
        table = measurement_table(suite.cases_of(study))
        if table is not None:
            sections.append((f"Measurements: {study}", f"What each case of study {study} measured at its end "
                             "(glossary at the end).", table))
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


def _per_level(row, value):
    """value(check) for each usable level of the row, NaN where its exact signal is not known
    (and for a row of fewer than two levels, which is not checked)."""
    if len(row.roundoff) != len(row.levels):
        return [float("nan")] * len(row.levels)
    return [float("nan") if c is None else value(c) for c in row.roundoff]


def order_row_values(r):
    """One row of orders.csv as values, in the order of ORDERS_CSV_COLUMNS (summary.json takes the same)."""
    finest = r.levels[-1] if r.levels else None
    return [r.study, r.series.label, r.norm, r.unit, r.time, r.series.refine, len(r.levels), len(r.left_out),
            *(v if r.has_order else float("nan") for v in (r.fit.order, r.fit.ci_low, r.fit.ci_high)),
            r.classification, finest.value if finest else "", finest.h if finest else "",
            finest.error if finest else ""]


def _write_csv(path, header, rows):
    """A CSV file of `header` and `rows`, whole or absent under `path` (gate_files.write_atomically)."""
    stream = io.StringIO(newline="")
    writer = csv.writer(stream)
    writer.writerow(header)
    writer.writerows(rows)
    write_atomically(path, stream.getvalue())


def write_orders_csv(rows, path):
    _write_csv(path, [name for name, _ in ORDERS_CSV_COLUMNS],
               ([repr(v) if isinstance(v, float) else v for v in order_row_values(r)] for r in rows))


def _levels_rows(rows):
    nan = float("nan")
    for r in rows:
        row = [r.study, r.series.label, r.norm, r.unit, repr(r.time), r.series.refine]
        pairwise = [nan] + list(r.pairwise) if r.has_order else [nan] * len(r.levels)
        relative = _per_level(r, lambda c: c.relative_error)
        floor = _per_level(r, lambda c: c.relative_floor)
        settling = _per_level(r, lambda c: c.relative_settling)
        for k, level in enumerate(r.levels):
            yield row + [level.value, repr(float(level.h)), repr(float(level.error)), 1, "", repr(float(pairwise[k])),
                         repr(float(relative[k])), repr(float(floor[k])), repr(float(settling[k]))]
        for level in r.left_out:
            yield row + [level.value, repr(float(level.h)), repr(nan), 0, level.reason, *[repr(nan)] * 4]


def write_levels_csv(rows, path):
    _write_csv(path, [name for name, _ in LEVELS_CSV_COLUMNS], _levels_rows(rows))


def write_gci_csv(rows, path):
    _write_csv(path, ["study", "series", "probe", "quantity", "time", "levels", "f_coarse", "f_medium", "f_fine",
                      "ratio", "observed_order", "convergence", "extrapolated", "gci_fine", "gci_medium",
                      "asymptotic_ratio", "exact"],
               ([r.study, r.series.label, r.probe, r.quantity, repr(r.time), ";".join(str(v) for v in r.levels),
                 *map(repr, r.values), repr(r.ratio), repr(r.convergence.observed_order), r.convergence.convergence,
                 repr(r.convergence.extrapolated), repr(r.convergence.gci_fine), repr(r.convergence.gci_medium),
                 repr(r.convergence.asymptotic_ratio), repr(r.exact)] for r in rows))
