"""Published numbers set beside the suite's own: the [[reference]] tables of a
suite file (suites/README.md). They check nothing (the gate ignores them); the
report shows them so that a reader sees, row by row, what another code reached
and what this one reached on the same case.

A reference names one or more studies, the scene keys that identify a row
(`columns`) and its rows: the keys' values, then the published number.

* quantity = "time_reached": the time the other code's run reached. Beside it,
  each matching case's time reached and, when it stopped early, why. Cases of a
  study that match one row are told apart by the study's other varying keys
  (e.g. method), each such group a column.
* quantity = "error": the error the other code reached, in the norm `norm`
  (an /errors column) at output time `time` (default: each case's end time).
  Beside it, each matching case's error in the same norm at the same time,
  grouped into columns as for time_reached.
* quantity = "order": the observed order the other code reported for `norm` at
  output time `time`. Beside it, each refinement series of the named studies
  whose cases all match the row: its usable levels, pairwise orders and
  least-squares order with its 95% interval (reports/orders.py).
"""
import math
from dataclasses import dataclass

from .series import canonical_value


@dataclass(frozen=True)
class Reference:
    source: str
    studies: tuple
    quantity: str                # "time_reached", "error" or "order"
    columns: tuple               # scene keys that identify a row
    rows: tuple                  # (key values tuple, published number)
    norm: str = ""
    time: float = float("nan")   # error and order; NaN: each case's (series') end time


class ReferenceError(ValueError):
    """A [[reference]] table the report cannot read; the message is one line."""


def read_references(tables):
    """The [[reference]] tables of suite.toml as Reference objects (mpmvv suite
    validated them before the run; this checks the shape again for hand-made
    directories)."""
    references = []
    for index, table in enumerate(tables or []):
        where = f"[[reference]] {index + 1}"
        if not isinstance(table, dict):
            raise ReferenceError(f"{where}: not a table")
        studies = table.get("study")
        studies = (studies,) if isinstance(studies, str) else tuple(studies or ())
        quantity = table.get("quantity")
        columns = tuple(table.get("columns", ()))
        if not studies or quantity not in ("time_reached", "error", "order"):
            raise ReferenceError(f"{where}: needs 'study' and 'quantity' (time_reached, error or order)")
        rows = []
        for row in table.get("rows", ()):
            if not isinstance(row, list) or len(row) != len(columns) + 1:
                raise ReferenceError(f"{where}: a row holds one value per column, then the {quantity}")
            rows.append((tuple(row[:-1]), float(row[-1])))
        time = table.get("time")
        references.append(Reference(str(table.get("source", "")), studies, quantity, columns, tuple(rows),
                                    str(table.get("norm", "")), float(time) if time is not None else float("nan")))
    return references


def row_matches(keys, columns, values):
    """True when the case keys hold every column's value (1 equals 1.0)."""
    return all(name in keys and canonical_value(keys[name]) == canonical_value(value) for name, value in zip(columns, values))


def row_label(columns, values):
    return ", ".join(f"{name}={value}" for name, value in zip(columns, values)) or "every case"


def group_keys(cases, columns):
    """The keys that vary among a study's cases, other than the row's columns, in
    first-seen order: they tell apart the cases that match one row."""
    names = list(dict.fromkeys(name for c in cases for name in c.keys if name not in columns))
    return [n for n in names if len({canonical_value(c.keys.get(n)) for c in cases}) > 1]


def reached_text(case):
    """The time a case reached, and why it stopped when it stopped early."""
    if case is None:
        return "-"
    if case.results is None:
        return case.status
    reached = f"{case.time_reached:.3g}"
    return reached if case.completed else f"{reached} {case.failure_reason or case.status}"


def case_table(suite, reference, cell_of, published_header):
    """(headers, rows, css): one row per published row, with its published number
    and a column per (study, group of the study's other varying keys) holding
    cell_of(case) for the case that matches the row, or "-"."""
    groups = []                  # (study, group key values, label)
    for study in reference.studies:
        cases = suite.cases_of(study)
        varying = group_keys(cases, reference.columns)
        for case in cases:
            values = tuple(canonical_value(case.keys.get(n)) for n in varying)
            label = study + "".join(f" {n}={case.keys.get(n)}" for n in varying)
            if (study, values, label) not in groups:
                groups.append((study, values, label))
    headers = list(reference.columns) + [published_header] + [label for _, _, label in groups]
    rows, css = [], []
    for values, published in reference.rows:
        cells = [str(v) for v in values] + [f"{published:g}"]
        for study, group, _ in groups:
            cases = suite.cases_of(study)
            varying = group_keys(cases, reference.columns)
            match = [c for c in cases if row_matches(c.keys, reference.columns, values)
                     and tuple(canonical_value(c.keys.get(n)) for n in varying) == group]
            cells.append(cell_of(match[0]) if match else "-")
        rows.append(cells)
        css.append("")
    return headers, rows, css


def time_reached_table(suite, reference):
    """(headers, rows, css): the published time and each matching case's time reached."""
    return case_table(suite, reference, reached_text, "reference [s]")


def error_table(suite, reference, lookup_error, unit):
    """(headers, rows, css): the published error and each matching case's error in
    the same norm at the reference's time (each case's end time when it names none),
    or why there is none. lookup_error(case, norm, time) is results.lookup_error."""
    def cell(case):
        time = reference.time if math.isfinite(reference.time) else case.end_time
        value, why = lookup_error(case, reference.norm, time)
        return f"{value:.3g}" if math.isfinite(value) else why
    return case_table(suite, reference, cell, f"reference [{unit}]")


def order_rows(suite, reference, series_of, order_row, unit_of):
    """(reference row, published order, OrderRow) for every refinement series of
    the named studies whose cases all match a published row. series_of(study) and
    order_row(series, norm, unit, time, at_end) are the report's own."""
    result = []
    for values, published in reference.rows:
        for study in reference.studies:
            for series in series_of(study):
                if not series.cases or not all(row_matches(c.keys, reference.columns, values) for c in series.cases):
                    continue
                end = next((c.end_time for c in series.cases if math.isfinite(c.end_time)), float("nan"))
                time = reference.time if math.isfinite(reference.time) else end
                result.append((values, published, order_row(series, reference.norm, unit_of(study), time,
                                                              math.isclose(time, end))))
    return result
