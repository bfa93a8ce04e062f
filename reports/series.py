"""Refinement series: the cases of a study that differ only in the key that
refines (suites/README.md, [[expect]]: "cases in which an expectation's refine
key varies and all other keys agree form one refinement series").

Rule, over a given set of cases (a study, or the cases an expectation's
`where` selects), using each case's resolved keys from manifest.json:

* a key *follows the refine key* when it varies among the cases but takes a
  single value at each value of the refine key (it was zipped with it, or an
  override sets it per level, e.g. a smaller cfl on the finest mesh);
* cases that agree on every other key form one series; the keys that vary
  between series name them (e.g. method=cpdi, amplitude=0.5);
* a series' levels are sorted by cell size h (results attribute `h`), coarse
  first; a case without results (pending, crashed, ...) has no h and takes its
  place by its refine value, in the direction h takes in the other cases.
"""
import json
import math
from dataclasses import dataclass

from .orders import pairwise_orders, roundoff_floor
from .results import lookup_error
from .scales import error_scale, settling_scale

DEFAULT_REFINE_KEY = "cells"


@dataclass(frozen=True)
class Series:
    study: str
    refine: str
    label_keys: dict      # the keys (and values) that tell this series from the others
    cases: tuple          # coarse first

    @property
    def label(self):
        """The keys that tell the series apart; for a lone series, its method when it has one (an
        external program's cases: "external program", whose method is its own, not the key's)."""
        keys = self.label_keys
        if not keys and self.cases and self.cases[0].keys.get("external_command"):
            return "external program"
        if not keys and self.cases and "method" in self.cases[0].keys:
            keys = {"method": self.cases[0].keys["method"]}
        return ", ".join(f"{key}={value}" for key, value in keys.items()) or "all cases"


# What a refine key other than the cell count refines, and the size it sets,
# the abscissa of an order fit (E = C size^p): the particle spacing h / ppd for
# particles per direction at fixed h (the marker refinement of
# 000_1dbcb8acb6dddab9.txt), the time step for cfl at fixed h (dt = cfl h /
# (wave speed + particle speed): in proportion to cfl h), and the load step
# (1 / load_steps) of an implicit run. Any other key is fitted against h.
REFINED_SIZES = {
    "particles_per_direction": ("particle spacing h / ppd [m]", lambda c: c.h / float(c.keys["particles_per_direction"])),
    "cfl": ("time step, as cfl h [m]", lambda c: float(c.keys["cfl"]) * c.h),
    "load_steps": ("load step 1 / load_steps", lambda c: 1.0 / float(c.keys["load_steps"])),
}
CELL_SIZE = "cell size h [m]"


def size_name(refine):
    """What an order against the refine key is fitted against."""
    return REFINED_SIZES[refine][0] if refine in REFINED_SIZES else CELL_SIZE


def refined_size(case, refine):
    """The case's size along the refine key (REFINED_SIZES; else its cell size h)."""
    if refine in REFINED_SIZES and math.isfinite(case.h):
        try:
            return REFINED_SIZES[refine][1](case)
        except (KeyError, TypeError, ValueError, ZeroDivisionError):
            return float("nan")
    return case.h


@dataclass(frozen=True)
class Level:
    case: object          # results.Case, or None for a requested level no case has
    value: object         # the refine key's value
    h: float              # the size the refine key sets (refined_size): h for cells
    error: float          # NaN when the level is not usable
    reason: str           # why the level is not usable; "" when it is


def matches(keys, where):
    """True when every key of `where` is among `keys` with an equal value."""
    return all(name in keys and keys[name] == value for name, value in where.items())


def canonical_value(value):
    """A hashable text for a key's value; 1 and 1.0 are the same value (a TOML echo may write either)."""
    return json.dumps(_as_float(value), sort_keys=True)


def _as_float(value):
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, list):
        return [_as_float(v) for v in value]
    if isinstance(value, dict):
        return {k: _as_float(v) for k, v in value.items()}
    return value


def refinement_series(cases, refine=DEFAULT_REFINE_KEY, named_first=()):
    """Split cases (of one study) into refinement series by the rule of the module docstring.
    Cases without the refine key are left out. Keys that vary together between
    series, one value of each with one value of the other (zipped, e.g. a
    stiffness ratio with the end time it needs), are named in the label by one
    of them: the first in `named_first` (the study's swept and zipped keys in file
    order), else the first."""
    cases = [c for c in cases if refine in c.keys]
    if not cases:
        return []
    names = list(dict.fromkeys(name for c in cases for name in c.keys if name != refine))
    varying = [n for n in names if len({canonical_value(c.keys.get(n)) for c in cases}) > 1]
    grouping = [n for n in varying if not _follows(cases, n, refine)]
    groups = {}
    for case in cases:
        groups.setdefault(tuple(canonical_value(case.keys.get(n)) for n in grouping), []).append(case)
    rank = {name: index for index, name in enumerate(named_first)}
    ordered = sorted(grouping, key=lambda n: (rank.get(n, len(rank)), grouping.index(n)))
    named = []
    for name in ordered:
        if not any(_one_to_one(cases, name, kept) for kept in named):
            named.append(name)
    return [Series(study=members[0].study, refine=refine,
                   label_keys={n: members[0].keys.get(n) for n in grouping if n in named},
                   cases=tuple(_coarse_first(members, refine)))
            for members in groups.values()]


def _one_to_one(cases, a, b):
    """True when each value of key a goes with one value of key b and the reverse."""
    pairs = {(canonical_value(c.keys.get(a)), canonical_value(c.keys.get(b))) for c in cases}
    return len(pairs) == len({p[0] for p in pairs}) == len({p[1] for p in pairs})


def _follows(cases, name, refine):
    refine_values = {canonical_value(c.keys[refine]) for c in cases}
    if len(refine_values) < 2:
        return False
    return all(len({canonical_value(c.keys.get(name)) for c in cases if canonical_value(c.keys[refine]) == r}) == 1
               for r in refine_values)


def _coarse_first(cases, refine):
    known = sorted((c for c in cases if math.isfinite(refined_size(c, refine))), key=lambda c: -refined_size(c, refine))
    numeric = all(isinstance(c.keys[refine], (int, float)) for c in cases)
    if len(known) == len(cases) or not numeric:
        return known + [c for c in cases if not math.isfinite(refined_size(c, refine))]
    h_falls_as_value_grows = len(known) < 2 or known[0].keys[refine] <= known[-1].keys[refine]
    return sorted(cases, key=lambda c: c.keys[refine] if h_falls_as_value_grows else -c.keys[refine])


def series_levels(series, norm, time=None, levels=None):
    """One Level per case of the series (restricted to the refine values `levels`
    when given, with a placeholder for a requested value no case has): its error
    `norm` at output time `time` (default: the case's end time), or why not."""
    chosen = list(series.cases)
    result = []
    if levels is not None:
        chosen = [c for c in chosen if c.keys[series.refine] in levels]
        present = [c.keys[series.refine] for c in chosen]
        result = [Level(None, v, float("nan"), float("nan"), f"no case with {series.refine}={v}")
                  for v in levels if v not in present]
    for case in chosen:
        error, reason = lookup_error(case, norm, case.end_time if time is None else time)
        result.append(Level(case, case.keys[series.refine], refined_size(case, series.refine), error, reason))
    return result


def usable(levels):
    return [level for level in levels if not level.reason]


# What may explain a level's error other than the method (RoundOff.floor_kind).
ROUNDOFF, SETTLING = "round-off", "settling"


@dataclass(frozen=True)
class RoundOff:
    """A usable level's error beside the exact signal it measures at the read time,
    the largest error rounding alone can leave there (reports/orders.py) and,
    for a run that settles to a static state, the largest its distance from
    that state at the end can leave (scales.settling_scale; None otherwise)."""
    level: Level
    signal: float         # S, in the norm's unit (1 for an error relative to its exact value; NaN: not known)
    floor: float          # case_roundoff_floor([the case], M)
    settling: float = None

    def _relative(self, value):
        # NaN where the signal is not known (a level checked for settling alone).
        if value is None or not math.isfinite(self.signal):
            return float("nan")
        return value / self.signal if self.signal > 0 else float("inf")

    @property
    def relative_error(self):
        return self._relative(self.level.error)

    @property
    def relative_floor(self):
        return self._relative(self.floor)

    @property
    def relative_settling(self):
        return self._relative(self.settling)

    @property
    def at_roundoff(self):
        # An error of exactly zero is not rounding: the gate asks whether the run measures the norm.
        return 0.0 < self.level.error <= self.floor

    @property
    def at_settling(self):
        return self.settling is not None and 0.0 < self.level.error <= self.settling

    @property
    def floor_kind(self):
        """ROUNDOFF, SETTLING (where rounding does not already explain the error), or None."""
        return ROUNDOFF if self.at_roundoff else SETTLING if self.at_settling else None


def roundoff_checks(levels, norm, time=None):
    """One RoundOff per usable level of `levels`, in order, at output time `time`
    (default: the case's end time); None for a level whose exact signal or
    coordinate size is not known (scales.error_scale) and that does not settle
    (scales.settling_scale)."""
    checks = []
    for level in usable(levels):
        case = level.case
        at = case.end_time if time is None else float(time)
        scale, settling = error_scale(case, norm, at), settling_scale(case, norm, at)
        if scale is not None:
            checks.append(RoundOff(level, scale[0], case_roundoff_floor([case], scale[1]), settling))
        elif settling is not None:
            checks.append(RoundOff(level, float("nan"), 0.0, settling))
        else:
            checks.append(None)
    return checks


def steps_of(case):
    """The steps the case's run took (its attribute `steps`), 0 where not known."""
    steps = case.attribute("steps", 0)
    return int(steps) if isinstance(steps, (int, float)) and math.isfinite(steps) else 0


def output_spacing_of(case):
    """The relative spacing of the numbers another program wrote for the case
    (/external attribute output_spacing, reports/orders.py), 0 for mpmvv's own run."""
    spacing = case.results.external.get("output_spacing", 0.0) if case.results is not None else 0.0
    return float(spacing) if isinstance(spacing, (int, float)) and math.isfinite(spacing) else 0.0


def case_roundoff_floor(cases, size):
    """orders.roundoff_floor of numbers of `size` for the worst of `cases`: the
    most steps any took, the coarsest spacing any external program wrote with."""
    return roundoff_floor(max((steps_of(c) for c in cases), default=0), size,
                          max((output_spacing_of(c) for c in cases), default=0.0))


def pair_order_cell(cases, norm, time, errors, sizes, width=9):
    """A table cell with the observed order between two levels (coarse, fine: their
    cases, errors of `norm` at output time `time`, and sizes h), or what explains
    either error in its place ("round-off", "settling": RoundOff.floor_kind)."""
    kind = floor_kind([_single_check(case, norm, time, error) for case, error in zip(cases, errors)])
    if kind:
        return f"{kind:>{width}}"
    return f"{pairwise_orders(list(sizes), list(errors))[0]:>{width}.2f}"


def error_floor_kind(case, norm, time, error):
    """What may explain `error`, the case's `norm` at output time `time`, other
    than the method (RoundOff.floor_kind), for tables that compare single results
    files."""
    check = _single_check(case, norm, time, error)
    return None if check is None else check.floor_kind


def _single_check(case, norm, time, error):
    """The RoundOff of one results file's `error` (roundoff_checks), or None."""
    [check] = roundoff_checks([Level(case, None, case.h, error, "")], norm, time)
    return check


def floor_kind(checks):
    """ROUNDOFF when some level's error is at round-off, else SETTLING when some
    level's is at the settling level, else None: the series' class then, and no
    order is given."""
    kinds = [c.floor_kind for c in checks if c is not None]
    return ROUNDOFF if ROUNDOFF in kinds else SETTLING if SETTLING in kinds else None


def floor_text(refine, checks):
    """Which levels among `checks` are at a floor and how small their errors are
    ("round-off at cells=88 (up to 9.4e-08 of the exact signal; round-off floor
    9.5e-08)", "the settling level at cells=44,88 (...)"), for a report cell or
    a gate reason; "" when none is."""
    kind = floor_kind(checks)
    if kind is None:
        return ""
    at = [c for c in checks if c is not None and c.floor_kind == kind]
    levels = ",".join(str(c.level.value) for c in at)
    if kind == ROUNDOFF:
        largest = max(at, key=lambda c: c.relative_error)
        return (f"round-off at {refine}={levels} (up to {largest.relative_error:.2g} of the exact signal; "
                f"round-off floor {largest.relative_floor:.2g})")
    ratio = max(c.settling / c.level.error for c in at)
    return (f"the settling level at {refine}={levels} (the run's distance from its static state at the end "
            f"could leave up to {ratio:.2g} times the error: the results file's /settling)")
