#!/usr/bin/python3
"""Convergence report of a suite output directory, from its results files only.

Usage: /usr/bin/python3 reports/report.py DIR [-o OUT]      (default OUT = DIR/report)

Writes
  OUT/report.html   self-contained (figures embedded as base64 PNG, no external links)
  OUT/report.md     the same text, figures linked from OUT/figures/*.png
  OUT/orders.csv    one row per (study, refinement series, error norm, output time)
  OUT/levels.csv    one row per level of each of those rows
  OUT/gci.csv       Richardson extrapolation and GCI of each series' point-probe value
  OUT/summary.json  every case's state, the gate's verdicts and orders.csv's rows in one file
                    (summary_file.py)

The columns of orders.csv and levels.csv are ORDERS_CSV_COLUMNS and LEVELS_CSV_COLUMNS
(report_rows.py); the report states them.

Norms are defined in reports/norms.py, orders, the classification rule and
the GCI in reports/orders.py, refinement series in reports/series.py.
"""
import argparse
import base64
import html
import sys
import time as clock
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from . import figure_parts
from . import gate
from . import orders
from . import report_tables
from . import verdict_figure
from .report_figures import external_comparison_figure, study_figures
from .report_rows import LEVELS_CSV_COLUMNS, ORDERS_CSV_COLUMNS, gci_rows, order_rows, stored_norm_check
from .report_tables import (case_table, expectation_table, gci_table, measurement_sections, orders_table,
                           reference_sections, write_gci_csv, write_levels_csv,
                           write_orders_csv)
from .results import Suite, SuiteDirectoryError, read_suite, require_suite_file
from .gate_files import write_atomically
from .summary_file import write_summary


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
    verdicts: list = None        # the gate's, when the suite has expectations and they could be checked
    gate_error: str = ""         # why they could not be
    glossary: str = ""           # what the tables' columns and classes mean, after the figures
    verdict_figure: object = None  # FigureEntry of every checked series against its band, under the verdict


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


def build_report(suite, figure_directory, progress=None):
    """The report of `suite`, its figures written to `figure_directory`;
    `progress(done, total, study)` is told before each study's figures and once
    more at the end (done == total, study None)."""
    rows, grid_rows = order_rows(suite), gci_rows(suite)
    # The gate's verdict first: what a reader asks before anything else.
    sections = []
    verdicts, gate_error = None, ""
    if suite.expectations:
        try:
            verdicts = gate.gate(suite)
            summary = gate.summary_line(verdicts, len(suite.expectations))
            sections.append(("Expectations", f"As checked by mpmvv gate: {summary}.", expectation_table(verdicts)))
        except SuiteDirectoryError as error:
            gate_error = str(error)
            sections.append(("Expectations", f"Not checked: {error}", None))
    sections.append(("Cases", "Status from manifest.json; time reached, failure reason, health verdict (for a run by "
                     "another program, the rules its output let mpmvv judge), wall time of the time loop, steps and "
                     "particle count from each results file.", case_table(suite)))
    sections += reference_sections(suite, rows)
    sections += measurement_sections(suite)
    fitted = [r for r in rows if len(r.levels) >= 2]
    sections.append(("Observed orders", f"Each series' orders by norm and output time; the columns and classes "
                     f"are defined in the glossary at the end. {len(rows) - len(fitted)} of {len(rows)} (series, "
                     "norm, time) combinations have fewer than two usable levels and are left out here; orders.csv "
                     "has every row.", orders_table(fitted)))
    sections.append(("Richardson extrapolation and grid convergence index",
                     "Roache's GCI (safety factor 1.25) of the point probe's simulated value on the three finest "
                     "completed levels of each series with a constant refinement ratio, at the output time where the "
                     "finest value is largest in magnitude, treated as a quantity without an exact value; the exact "
                     "value is shown only to check the band f_fine (1 +- GCI). Convergence round-off: a change between "
                     f"two levels is at most ({orders.ROUNDOFF_ULPS} + steps) ulps of the point's |X| (pi for an "
                     "angle), which rounding alone can explain: no order, extrapolation or GCI.", gci_table(grid_rows)))
    # Definitions once, at the end, rather than above every table they serve.
    measured = any(title.startswith("Measurements: ") for title, _, _ in sections)
    glossary = (DEFINITIONS + (" Measurements: " + report_tables.MEASUREMENTS_DEFINITION if measured else "") +
                " orders.csv has every (series, norm, time) row, with the columns " +
                "; ".join(f"{n} ({m})" for n, m in ORDERS_CSV_COLUMNS) +
                "; levels.csv each row's levels, one per line, with the columns " +
                "; ".join(f"{n} ({m})" for n, m in LEVELS_CSV_COLUMNS[6:]) + ".")
    entries, studies = [], suite.study_names()
    for done, study in enumerate(studies):
        if progress:
            progress(done, len(studies), study)
        entries += study_figures(suite, study, rows, figure_directory)
    comparison = external_comparison_figure(suite, figure_directory)
    if progress:
        progress(len(studies), len(studies), None)
    if comparison is not None:
        entries.insert(0, comparison)
    summary = verdict_figure.verdict_figure(verdicts, figure_directory, suite.name) if verdicts else None
    return Report(suite, datetime.now(), status_counts(suite), stored_norm_check(suite), rows, grid_rows,
                  sections, entries, verdicts, gate_error, glossary, summary)


FIGURE_LIST = ".figures-written"   # in OUT/figures: the figures this report wrote, the next one replaces
PROBLEMS_SHOWN = 20   # result problems listed on the report's first screen


def verdict_lines(report):
    """The gate's verdict in a line (PASS, FAIL, not checked, or no expectations),
    then one line for each series that fell short: what the report opens with."""
    suite = report.suite
    if suite.problems:
        # Results not checked to be their cases' (consistency.py): no verdict rests on them.
        shown = suite.problems[:PROBLEMS_SHOWN]
        more = len(suite.problems) - len(shown)
        return "fail", [f"Verdict: FAIL. {len(suite.problems)} result(s) are not their cases' or are damaged; "
                        "their numbers are left out of every table and figure below:"] + shown + \
            ([f"and {more} more (mpmvv gate lists them all)"] if more > 0 else [])
    if not suite.expectations:
        return "none", ["Verdict: none. This suite has no [[expect]], so it gates nothing; its cases and "
                        "figures follow."]
    if report.verdicts is None:
        return "fail", [f"Verdict: not checked: {report.gate_error}"]
    summary = gate.summary_line(report.verdicts, len(suite.expectations))
    summary = summary[0].upper() + summary[1:]
    short = [v for v in report.verdicts if not v.passed]
    if not short:
        return "pass", [f"Verdict: PASS. {summary}."]
    lines = [f"Verdict: FAIL. {summary}:"]
    for v in short:
        row = dict(zip(gate.HEADER, gate.verdict_row(v)))
        lines.append(f"expectation {row['#']} ({row['study']}, {row['series']}, {row['norm']} at t = {row['t']}): "
                     f"observed {row['observed order [95% CI]']}, expected {row['expected']}: {row['reason']}")
    return "fail", lines


def header_lines(report):
    suite = report.suite
    counts = ", ".join(f"{n} {s}" for s, n in report.status_counts.items())
    checked, largest = report.norm_check
    tier = ("the full study" if suite.tier == "full" else
            "the ci tier: the cheap levels and expectations every merge runs (the full study has more)")
    return [
        suite.description or "(no description in suite.toml)",
        f"Tier: {tier}.",
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
div.table { overflow-x: auto; max-width: 100%; }
div.verdict { border-left: 6px solid #888; background: #f6f6f6; padding: 0.3em 1em; margin: 0.5em 0 1em; }
div.verdict.pass { border-color: #1a7f37; background: #eef8f0; }
div.verdict.fail { border-color: #c62828; background: #fdeeee; }
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
    # A table wider than the page scrolls inside its own box (the uniaxial
    # suite's measurements were cut at the window's edge).
    return f"<div class='table'><table{kind}><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table></div>"


def _html_figure(entry):
    data = base64.b64encode(entry.path.read_bytes()).decode()
    return (f"<figure><img alt='{html.escape(entry.path.name)}' src='data:image/png;base64,{data}'>"
            f"<figcaption>{html.escape(entry.caption)}</figcaption></figure>")


def render_html(report):
    suite = report.suite
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(suite.name)}</title>"
             f"<style>{CSS}</style></head><body><h1>Convergence report: {html.escape(suite.name)}</h1>"]
    kind, verdict = verdict_lines(report)
    parts.append(f"<div class='verdict {kind}'><p><strong>{html.escape(verdict[0])}</strong></p>" +
                 ("<ul>" + "".join(f"<li>{html.escape(line)}</li>" for line in verdict[1:]) + "</ul>"
                  if len(verdict) > 1 else "") + "</div>")
    if report.verdict_figure is not None:
        parts.append(_html_figure(report.verdict_figure))
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
            parts.append(_html_figure(entry))
    if report.glossary:
        parts.append(f"<h2>Glossary</h2><p>{html.escape(report.glossary)}</p>")
    parts.append("</body></html>")
    return "\n".join(parts)


def markdown_table(table):
    escape = lambda cell: cell.replace("|", "\\|").replace("\n", " ")  # noqa: E731
    lines = ["| " + " | ".join(table.headers) + " |", "|" + "---|" * len(table.headers)]
    lines += ["| " + " | ".join(escape(cell) for cell in row) + " |" for row in table.rows]
    return "\n".join(lines)


def render_markdown(report, output_directory):
    lines = [f"# Convergence report: {report.suite.name}", ""]
    _, verdict = verdict_lines(report)
    lines += [f"**{verdict[0]}**", ""] + [f"- {line}" for line in verdict[1:]] + ([""] if len(verdict) > 1 else [])
    if report.verdict_figure is not None:
        entry = report.verdict_figure
        lines += [f"![{entry.caption}]({entry.path.relative_to(output_directory).as_posix()})", "",
                  f"_{entry.caption}_", ""]
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
    if report.glossary:
        lines += ["## Glossary", "", report.glossary, ""]
    return "\n".join(lines)


def write_report(directory, output=None, progress=None):
    """Read the suite, write every output; returns the paths written
    (`progress` as for build_report)."""
    suite = directory if isinstance(directory, Suite) else read_suite(directory)
    output = Path(output) if output else suite.directory / "report"
    figure_directory = output / "figures"
    made = not figure_directory.exists()
    figure_directory.mkdir(parents=True, exist_ok=True)
    try:
        return _write_outputs(suite, output, figure_directory, progress)
    except OSError:
        # A full disk or a read-only place: leave no empty folder behind.
        if made and not any(figure_directory.iterdir()):
            figure_directory.rmdir()
        raise


def _write_outputs(suite, output, figure_directory, progress):
    """write_report's outputs, into `output` and its `figures`."""
    # Only the figures an earlier report wrote here go (FIGURE_LIST names
    # them): a file of the user's in the same folder stays.
    listed = figure_directory / FIGURE_LIST
    if listed.is_file():
        for name in listed.read_text().splitlines():
            if name and "/" not in name and name.endswith(".png"):
                (figure_directory / name).unlink(missing_ok=True)
    before = {p.name: p.stat().st_mtime_ns for p in figure_directory.glob("*.png")}
    report = build_report(suite, figure_directory, progress)
    written_figures = sorted(p.name for p in figure_directory.glob("*.png")
                             if before.get(p.name) != p.stat().st_mtime_ns)
    write_atomically(listed, "".join(f"{name}\n" for name in written_figures))
    written = {"html": output / "report.html", "markdown": output / "report.md",
               "orders": output / "orders.csv", "levels": output / "levels.csv", "gci": output / "gci.csv",
               "summary": output / "summary.json"}
    # Whole or absent under their names (a full disk leaves no half page).
    write_atomically(written["html"], render_html(report))
    write_atomically(written["markdown"], render_markdown(report, output))
    write_orders_csv(report.order_rows, written["orders"])
    write_levels_csv(report.order_rows, written["levels"])
    write_gci_csv(report.gci_rows, written["gci"])
    write_summary(written["summary"], report)
    return written, sum(e.path is not None for e in report.figures) + (report.verdict_figure is not None)


class _OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"mpmvv report: {message} (see --help)\n")


def main(argv):
    parser = _OneLineParser(prog="mpmvv report", description="Tables, figures and report.html of a suite output "
                            "directory, from its results files only.",
                            epilog="Exit 0: written; 1: written, but some results are not their cases' or are "
                                   "damaged (listed on stderr and first in the report; reports/consistency.py); "
                                   "2: not a suite directory, or the report cannot be written.")
    parser.add_argument("directory", metavar="DIR", help="a suite output directory (mpmvv suite SUITE -o DIR)")
    parser.add_argument("-o", "--output", metavar="OUT", help="where to write (default DIR/report)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress lines on stderr")
    args = parser.parse_args(argv)
    if args.output is not None and not args.output.strip():
        print(f"mpmvv report: -o {args.output!r}: an empty directory name; give the directory to write "
              "(without -o: DIR/report)", file=sys.stderr)
        return 2
    start, figures_before = clock.perf_counter(), figure_parts.written["figures"]

    def progress(done, total, study):
        """One line on stderr per study: how many studies are done, the figures so far, the time."""
        now = f"{figure_parts.written['figures'] - figures_before} figures, {clock.perf_counter() - start:.0f} s"
        step = f"study {done + 1} of {total}: {study}" if study is not None else f"{total} of {total} studies"
        print(f"mpmvv report: {step} ({now})", file=sys.stderr, flush=True)

    try:
        suite = read_suite(args.directory)
        require_suite_file(suite, "the report")
        written, figure_count = write_report(suite, args.output, None if args.quiet else progress)
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
    # Results that are not their cases': the report says so first, and so does its exit.
    gate.print_problems(suite, "mpmvv report")
    return 1 if suite.problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
