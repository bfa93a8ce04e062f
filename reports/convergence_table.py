#!/usr/bin/python3
"""Convergence table of ring results files: the L1 error of eq. 3.1
(000_1dbcb8acb6dddab9.txt) on each probe line and the volume-weighted particle
L1 at every output time, against the cell size h, with the observed order
p = log(E_coarse / E_fine) / log(h_coarse / h_fine) between consecutive meshes,
or "round-off" in its place when either error is at round-off (reports/orders.py:
rounding alone can explain it, and the ratio measures the rounding).

Usage: /usr/bin/python3 reports/convergence_table.py RESULTS.h5 [RESULTS.h5 ...]
"""
import sys

from .results import read_results_file
from .series import pair_order_cell

# The /errors columns tabulated, by their heading.
NORMS = {"L1 Theta=0": "L1_theta0", "L1 +45": "L1_theta_plus45", "L1 -45": "L1_theta_minus45",
         "particle L1": "particle_L1"}


def read_case(path):
    case = read_results_file(path)
    attributes, errors = case.results.attributes, case.results.errors
    return {
        "path": path,
        "h": float(attributes["h"]),
        "cells": int(attributes["cells"]),
        "method": attributes["method"],
        "status": attributes["status"],
        "time_reached": float(attributes["time_reached"]),
        "failure_reason": attributes["failure_reason"],
        "wall": float(attributes["wall_time_s"]),
        "time": list(case.results.error_times),
        "norms": {heading: list(errors[column]) for heading, column in NORMS.items()},
        "case": case,
    }


def main(paths):
    if not paths:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    cases = sorted((read_case(p) for p in paths), key=lambda c: -c["h"])
    print(f"{'cells':>6} {'h [m]':>9} {'method':>7} {'status':>10} {'reached':>8} {'wall [s]':>9}")
    for c in cases:
        status = c["status"] if c["status"] == "completed" else f"{c['status']} ({c['failure_reason']})"
        print(f"{c['cells']:>6} {c['h']:>9.4g} {c['method']:>7} {status:>10} {c['time_reached']:>8.4g} {c['wall']:>9.3g}")
    times = cases[0]["time"]
    for norm in cases[0]["norms"]:
        print(f"\n{norm} (rad for probe lines, m for particles); order p between consecutive meshes")
        header = f"{'t [s]':>7}" + "".join(f" {'h=' + format(c['h'], '.4g'):>12}" for c in cases)
        header += "".join(f" {'p':>9}" for _ in cases[1:])
        print(header)
        for k, t in enumerate(times):
            values = [c["norms"][norm][k] if k < len(c["time"]) else float("nan") for c in cases]
            row = f"{t:>7.3g}" + "".join(f" {v:>12.4e}" for v in values)
            for a, b in zip(range(len(cases) - 1), range(1, len(cases))):
                row += " " + pair_order_cell((cases[a]["case"], cases[b]["case"]), NORMS[norm], t,
                                             (values[a], values[b]), (cases[a]["h"], cases[b]["h"]))
            print(row)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
