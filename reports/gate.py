#!/usr/bin/python3
"""Gate a suite output directory on its expectations (suites/README.md, [[expect]]).

For every [[expect]] of the suite (as DIR/manifest.json records them): take the cases of its study whose
resolved keys match every entry of `where`; split them into refinement series
(reports/series.py); in each series take the levels (values of `refine`,
default "cells"; all, or those listed in `levels`) sorted by cell size h, read
the error `norm` at output `time` (default: each case's end time) from /errors,
and fit the least-squares order of ln E against ln h (reports/orders.py). The
expectation holds for a series when

* the fitted order lies in [order - tolerance, order + tolerance] (when an
  order is given);
* no usable level's error is at round-off (when an order is given): at most
  the round-off floor of reports/orders.py, (256 + steps) ulps of the numbers
  the error is a difference of. Such a series has no order to observe; the
  row says so, with the error over the exact signal it measures, and shows no
  fitted order. An expectation on max_error alone is not affected;
* max over the levels of E / h^order <= max_error_constant (when given);
* every usable level's E <= max_error (when given; an expectation gives an
  order with its tolerance, or max_error, or both, or at_roundoff);
* every usable level's E is at round-off (when at_roundoff = true: a patch
  test, whose motion the method reproduces): above zero and at most the
  round-off floor; a level whose floor is not known (reports/scales.py has
  no size for the norm) fails, named;
* every level's case completed (when must_complete, the default), that is
  neither failed nor lost its solution (the results file's health verdict);
* at least two levels are usable (have a finite error at that time, and not
  from the time a lost run's solution was lost on);
* the fit's 95 % confidence interval lies within the band (when
  interval_within_band; it needs three or more levels). Without it, an
  interval that reaches outside the band is noted beside a PASS.

A read where the exact quantity the norm measures (the mean |exact| on an
L1_<line> norm's line, the RMS exact displacement for particle_L1, _L2,
_Linf) is below TRIVIAL_SIGNAL (5 %) of its largest over the run is warned
about in the row: a run without the motion would score nearly the same there.

Before any of that, every result is checked against its case
(reports/consistency.py: status, keys, one file per case, the time axis, the
norms' values, paths inside DIR); a result that fails is named on stderr, its
numbers are not used, and the gate fails.

Prints one row per (expectation, series) and a closing line; exit 0 when every
expectation holds and every result is its case's, 1 otherwise, 2 (one line) when DIR is not a
readable suite output directory. The [[expect]] tables are the manifest's, which
`mpmvv suite` checked when it loaded the suite (its one check of them), and
which must equal those suite.toml gives for the tier (results.read_suite
refuses them otherwise). A --json or --junit file that cannot be written is
exit 2 naming it.

With --junit FILE and --json FILE the same verdicts are also written for CI
systems (reports/gate_files.py).

Usage: mpmvv gate DIR [--junit FILE] [--json FILE]
"""
import argparse
import math
import sys
from dataclasses import dataclass

from .orders import OrderFit, least_squares_order
from .results import SuiteDirectoryError, read_suite, require_suite_file
from .scales import exact_signal_fraction
from .series import (DEFAULT_REFINE_KEY, Series, floor_kind, floor_text, matches, refinement_series,
                    roundoff_checks, series_levels, size_name, usable)

TRIVIAL_SIGNAL = 0.05   # an exact signal below this fraction of its largest is warned about


@dataclass(frozen=True)
class Verdict:
    number: int                 # 1-based position of the [[expect]] in suite.toml
    expectation: dict
    series: Series              # None when no case matched
    levels: tuple               # series.Level, coarse first
    fit: OrderFit
    error_constant: float       # max over usable levels of E / h^order
    reasons: tuple              # why it fell short; empty when it holds
    notes: tuple                # levels left out of a passing fit, an interval reaching outside the band
    warnings: tuple = ()        # a read where the exact signal is trivial (TRIVIAL_SIGNAL)
    floor: str = None           # "round-off" or "settling" where some usable level's error is at it: no order is given

    @property
    def passed(self):
        return not self.reasons


def check_expectation(number, expect, suite):
    """One Verdict per refinement series among the cases the expectation selects."""
    where = expect.get("where", {})
    refine = expect.get("refine", DEFAULT_REFINE_KEY)
    cases = [c for c in suite.cases_of(expect["study"]) if matches(c.keys, where)]
    nan_fit = least_squares_order([], [])
    if not cases:
        return [Verdict(number, expect, None, (), nan_fit, float("nan"),
                        (f"no case of study '{expect['study']}' matches where = {where}",), ())]
    all_series = refinement_series(cases, refine, suite.varied_keys(expect["study"]))
    if not all_series:
        return [Verdict(number, expect, None, (), nan_fit, float("nan"),
                        (f"no matched case has the refine key '{refine}'",), ())]
    return [check_series(number, expect, s) for s in all_series]


def check_series(number, expect, series):
    levels = series_levels(series, expect["norm"], expect.get("time"), expect.get("levels"))
    good = usable(levels)
    fit = least_squares_order([l.h for l in good], [l.error for l in good])
    has_order = "order" in expect
    # An order fitted through a level whose error rounding, or the solver's
    # settling short of the static state, alone can explain measures that: such
    # an order is never passed (reports/orders.py).
    at_roundoff = bool(expect.get("at_roundoff", False))
    checks = roundoff_checks(levels, expect["norm"], expect.get("time")) if has_order or at_roundoff else []
    floor = floor_kind(checks)
    order = float(expect["order"]) if has_order else float("nan")
    tolerance = float(expect["tolerance"]) if has_order else float("nan")
    constant = max((l.error / l.h ** order for l in good), default=float("nan")) if has_order else float("nan")
    reasons, notes = [], []
    if expect.get("must_complete", True):
        unfinished = [l for l in levels if l.case is None or not l.case.completed]
        if unfinished:
            reasons.append("not completed: " + "; ".join(_level_outcome(series, l) for l in unfinished))
    bound = expect.get("max_error")
    if bound is not None:
        above = [l for l in good if not l.error <= bound]
        if above:
            reasons.append("error above " + f"{bound:g}: " + ", ".join(f"{series.refine}={l.value}: {l.error:.3g}"
                                                                      for l in above))
    # A bound on the error itself, or round-off, needs one usable level.
    if (bound is not None or at_roundoff) and not good:
        reasons.append("no usable level" + _left_out(series, levels))
    if at_roundoff:
        reasons.extend(_roundoff_reasons(series, good, checks, expect["norm"]))
    if not has_order:
        pass
    elif len(good) < 2:
        reasons.append(f"{len(good)} usable level(s), need 2" + _left_out(series, levels))
    elif not math.isfinite(fit.order):
        zero = [l for l in good if not l.error > 0]
        if zero:
            reasons.append("the error is exactly zero at " + ", ".join(f"{series.refine}={l.value}" for l in zero)
                           + ": no order can be fitted (does the run measure this norm?)")
        else:
            reasons.append(f"{size_name(series.refine).split(' [')[0]} does not vary over the usable levels: no order")
    elif floor:
        reasons.append(f"errors at {floor_text(series.refine, checks)}: no order can be observed; "
                       "check max_error instead")
    elif not order - tolerance <= fit.order <= order + tolerance:
        reasons.append(f"order {fit.order:.3f} outside [{order - tolerance:g}, {order + tolerance:g}]")
    interval_notes = []
    if has_order and math.isfinite(fit.order) and not floor:
        band = f"[{order - tolerance:g}, {order + tolerance:g}]"
        inside = order - tolerance <= fit.ci_low and fit.ci_high <= order + tolerance
        if expect.get("interval_within_band", False):
            if not math.isfinite(fit.ci_low):
                reasons.append(f"{len(good)} usable levels give no confidence interval; interval_within_band needs 3")
            elif not inside:
                reasons.append(f"95% interval [{fit.ci_low:.2f}, {fit.ci_high:.2f}] not within {band}")
        elif math.isfinite(fit.ci_low) and not inside:
            interval_notes.append(f"its 95% interval [{fit.ci_low:.2f}, {fit.ci_high:.2f}] reaches outside {band}")
    limit = expect.get("max_error_constant")
    if limit is not None and math.isfinite(constant) and constant > limit:
        reasons.append(f"E/h^{order:g} = {constant:.3g} > {limit:g}")
    if len(good) >= (2 if has_order else 1):
        notes = interval_notes + [f"left out {series.refine}={l.value} ({l.reason})" for l in levels if l.reason]
        # The report's figure fits every usable level of the series: where the
        # expectation names fewer, the two orders differ, and both say which.
        if has_order and "levels" in expect:
            every = usable(series_levels(series, expect["norm"], expect.get("time")))
            if [l.value for l in every] != [l.value for l in good]:
                notes.append(f"fitted on {series.refine}={','.join(str(l.value) for l in good)}; the report's "
                             f"figure fits all {len(every)} usable levels")
    read_time = expect.get("time")
    fractions = [f for f in (exact_signal_fraction(l.case, expect["norm"],
                                                   l.case.end_time if read_time is None else float(read_time))
                             for l in good) if f is not None]
    warnings = ()
    if fractions and min(fractions) < TRIVIAL_SIGNAL:
        warnings = (f"warning: read where the exact signal is {100 * min(fractions):.3g} % of its largest "
                    f"(a run without the motion would score nearly the same)",)
    return Verdict(number, expect, series, tuple(levels), fit, constant, tuple(reasons), tuple(notes), warnings,
                   floor)


def _left_out(series, levels):
    """ " (cells=32: why; ...)" for the levels left out of a series, "" when none is."""
    left_out = [f"{series.refine}={l.value}: {l.reason}" for l in levels if l.reason]
    return f" ({'; '.join(left_out)})" if left_out else ""


def _roundoff_reasons(series, good, checks, norm):
    """Why the usable levels' (`good`, with their `checks`) errors are not all at
    round-off (at_roundoff), each named."""
    reasons = []
    for level, check in zip(good, checks):
        where = f"{series.refine}={level.value}"
        if check is None or not math.isfinite(check.floor) or not check.floor > 0.0:
            reasons.append(f"{where}: no round-off floor is known for {norm}")
        elif not level.error > 0.0:
            reasons.append(f"{where}: the error is exactly zero (does the run measure {norm}?)")
        elif not check.at_roundoff:
            reasons.append(f"{where}: E = {level.error:.3g} is {level.error / check.floor:.3g} times the round-off "
                           f"floor {check.floor:.3g}")
    return reasons


def _level_outcome(series, level):
    if level.case is None:
        return level.reason
    case = level.case
    if case.problems:
        return f"{series.refine}={level.value} results not its case's ({'; '.join(case.problems)})"
    outcome = case.status
    if case.status == "failed" and math.isfinite(case.time_reached):
        outcome += f" at t = {case.time_reached:.3g}"
    if case.failure_reason:
        outcome += f" ({case.failure_reason})"
    return f"{series.refine}={level.value} {outcome}"


def series_description(where, series):
    """The keys that select the series: the expectation's `where` and the keys that vary between its series."""
    keys = dict(where)
    keys.update(series.label_keys if series else {})
    if not keys:
        return series.label if series else "all cases"
    return ", ".join(f"{key}={value}" for key, value in keys.items())


def _end_time_text(series):
    ends = {c.end_time for c in series.cases if math.isfinite(c.end_time)} if series else set()
    return f"{ends.pop():g} (end)" if len(ends) == 1 else "end"


def verdict_row(verdict):
    """The table cells of one verdict."""
    expect = verdict.expectation
    fit = verdict.fit
    # An expectation on the error alone (max_error, for errors at round-off or
    # settling level) claims no order, and a series at either has none: none
    # is shown beside them.
    shown = "order" in expect and math.isfinite(fit.order) and not verdict.floor
    observed = f"{fit.order:.3f}" if shown else f"- ({verdict.floor})" if verdict.floor else "-"
    if shown and math.isfinite(fit.ci_low):
        observed += f" [{fit.ci_low:.2f}, {fit.ci_high:.2f}]"
    used = [str(l.value) for l in verdict.levels if not l.reason]
    limit = expect.get("max_error_constant")
    constant = "-" if not math.isfinite(verdict.error_constant) else f"{verdict.error_constant:.3g}"
    if limit is not None:
        constant += f" <= {limit:g}"
    if "order" in expect:
        expected = f"[{float(expect['order']) - float(expect['tolerance']):g}, " \
                   f"{float(expect['order']) + float(expect['tolerance']):g}]"
    else:
        expected = "-"
    if "max_error" in expect:
        largest = max((l.error for l in verdict.levels if not l.reason), default=float("nan"))
        constant = ("-" if not math.isfinite(largest) else f"E = {largest:.3g}") + f" <= {expect['max_error']:g}"
    if expect.get("at_roundoff", False):
        expected = "round-off"
        largest = max((l.error for l in verdict.levels if not l.reason), default=float("nan"))
        constant = ("-" if not math.isfinite(largest) else f"E = {largest:.3g}") + " <= floor"
    return [
        str(verdict.number),
        expect["study"],
        series_description(expect.get("where", {}), verdict.series),
        expect["norm"],
        f"{expect['time']:g}" if "time" in expect else _end_time_text(verdict.series),
        ",".join(used) or "-",
        observed,
        expected,
        constant,
        "PASS" if verdict.passed else "FAIL",
        "; ".join(verdict.warnings + (verdict.reasons or verdict.notes)),
    ]


HEADER = ["#", "study", "series", "norm", "t", "levels", "observed order [95% CI]", "expected",
          "E/h^p or E", "status", "reason"]


def format_table(rows):
    widths = [max(len(r[i]) for r in [HEADER] + rows) for i in range(len(HEADER))]
    lines = ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in [HEADER] + rows]
    lines.insert(1, "  ".join("-" * width for width in widths))
    return "\n".join(lines)


def summary_line(verdicts, expectation_count):
    failed_expectations = len({v.number for v in verdicts if not v.passed})
    failed_series = sum(not v.passed for v in verdicts)
    if failed_expectations == 0:
        return f"all {expectation_count} expectations hold ({len(verdicts)} series checked)"
    return (f"{failed_expectations} of {expectation_count} expectations fell short "
            f"({failed_series} of {len(verdicts)} series)")


def gate(suite):
    """All verdicts of a suite, in suite-file order."""
    return [v for number, expect in enumerate(suite.expectations, start=1)
            for v in check_expectation(number, expect, suite)]


class _OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"mpmvv gate: {message} (see --help)\n")


def main(argv):
    parser = _OneLineParser(prog="mpmvv gate", description=__doc__.split("\n\n")[0],
                            epilog="Exit 0: every expectation holds; 1: one fell short; 2: bad directory or suite.")
    parser.add_argument("directory", metavar="DIR", help="a suite output directory (mpmvv suite SUITE -o DIR)")
    parser.add_argument("--junit", metavar="FILE", help="also write the verdicts as JUnit XML (reports/gate_files.py)")
    parser.add_argument("--json", metavar="FILE", help="also write the verdicts and their numbers as JSON")
    args = parser.parse_args(argv)
    for option, path in (("--junit", args.junit), ("--json", args.json)):
        if path is not None and not path:
            print(f"mpmvv gate: {option} '': an empty file name; give the file to write", file=sys.stderr)
            return 2
    try:
        suite = read_suite(args.directory)
        require_suite_file(suite, "the gate")
        if not suite.expectations_recorded:
            raise SuiteDirectoryError(f"{suite.directory / 'manifest.json'}: records no expectations (an mpmvv "
                                      "older than the record wrote it); run the suite again with the same "
                                      "command (its finished cases are kept) to record them")
        verdicts = gate(suite)
    except SuiteDirectoryError as error:
        print(f"mpmvv gate: {error}", file=sys.stderr)
        return 2
    from .gate_files import write_json, write_junit
    for path, write in ((args.junit, write_junit), (args.json, write_json)):
        if path:
            try:
                write(path, suite, verdicts)
            except OSError as error:
                print(f"mpmvv gate: cannot write {path}: {error.strerror or error}", file=sys.stderr)
                return 2
    name = suite.name if suite.tier == "full" else f"{suite.name} ({suite.tier} tier)"
    print_problems(suite, "mpmvv gate")
    if not suite.expectations:
        print(f"{name}: no [[expect]] in the suite; nothing to check")
        return 1 if suite.problems else 0
    print(f"{name}: {len(suite.expectations)} expectations")
    print(format_table([verdict_row(v) for v in verdicts]))
    print(summary_line(verdicts, len(suite.expectations)) +
          (f"; FAIL: {len(suite.problems)} result problem(s) above" if suite.problems else ""))
    return 0 if all(v.passed for v in verdicts) and not suite.problems else 1


def print_problems(suite, program):
    """The results not checked to be their cases' (reports/consistency.py), each
    on a line of stderr: they make the verdict FAIL, whatever the rows say."""
    if not suite.problems:
        return
    print(f"{program}: {suite.directory}: {len(suite.problems)} result(s) not their cases' or damaged; "
          "no verdict rests on them and the gate fails:", file=sys.stderr)
    for problem in suite.problems:
        print(f"  {problem}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
