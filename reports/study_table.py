#!/usr/bin/python3
"""Status and error of results files, grouped by scene, amplitude, variant and
method: whether each run completed (or when and why it stopped), its wall
time, chosen error norms at chosen times, and the observed order between
consecutive meshes of the same group ("round-off" in its place when either
error is at round-off, reports/orders.py: the ratio measures the rounding).

Usage: /usr/bin/python3 reports/study_table.py [--times 0.25,1.0]
           [--norms L1_theta0,particle_L2] RESULTS.h5 ...
Without --times: the scene's end time. Without --norms: the first probe line's
L1 (eq. 3.1 of 000_1dbcb8acb6dddab9.txt) and the particle L2 norm.
"""
import argparse
import sys
from collections import defaultdict

from .results import read_results_file
from .series import pair_order_cell

METHOD_ORDER = {"linear": 0, "gimp": 1, "cpdi": 2, "cpdi-exact": 3, "bspline": 4, "bspline-cubic": 5}


def read_case(path, times, norms):
    case = read_results_file(path)
    attrs, errors = case.results.attributes, case.results.errors
    recorded = list(case.results.error_times)
    chosen = norms or [next(iter(errors)), "particle_L2"]
    wanted = times or [float(attrs["end_time"])]
    values = {}
    for norm in chosen:
        series = list(errors.get(norm, []))
        for t in wanted:
            hits = [k for k, r in enumerate(recorded) if abs(r - t) < 1e-12 * max(1.0, abs(t))]
            values[(norm, t)] = series[hits[0]] if hits and hits[0] < len(series) else float("nan")
    return {
        "scene": str(attrs.get("scene", "ring")),
        # None, not NaN, for a scene without one: NaN would make every file a group of its own.
        "amplitude": float(attrs["amplitude"]) if "amplitude" in attrs else None,
        "variant": str(attrs.get("variant", "")),
        "extra": f"R_i={float(attrs['inner_radius']):g}" if attrs.get("scene") == "rz-cylinder" else "",
        "method": str(attrs["method"]),
        "cells": int(attrs["cells"]),
        "ppd": int(attrs["particles_per_direction"]),
        "h": float(attrs["h"]),
        "status": str(attrs["status"]),
        "reason": str(attrs["failure_reason"]),
        "failure_time": float(attrs["failure_time"]),
        "wall": float(attrs["wall_time_s"]),
        "forcing": float(attrs.get("forcing_time_s", float("nan"))),
        "steps": int(attrs["steps"]),
        "columns": [(norm, t) for norm in chosen for t in wanted],
        "values": values,
        "case": case,
    }


def order_cell(coarse, fine, key):
    """The order between two meshes (blank for the first), or "round-off" when either error is at round-off."""
    if coarse is None:
        return f"{float('nan'):>9.2f}"
    norm, time = key
    return pair_order_cell((coarse["case"], fine["case"]), norm, time,
                           tuple(c["values"].get(key, float("nan")) for c in (coarse, fine)),
                           (coarse["h"], fine["h"]))


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--times", default="", help="output times to tabulate (default: the last)")
    parser.add_argument("--norms", default="", help="error columns (default: first probe line L1, particle_L2)")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args(argv)
    times = [float(t) for t in args.times.split(",")] if args.times else []
    norms = args.norms.split(",") if args.norms else []
    groups = defaultdict(list)
    for path in args.files:
        c = read_case(path, times, norms)
        groups[(c["scene"], c["variant"], c["extra"], c["amplitude"], c["ppd"], c["method"])].append(c)
    for key in sorted(groups, key=lambda k: (k[0], k[1], k[2], k[3] is not None, k[3] or 0.0, k[4],
                                             METHOD_ORDER.get(k[5], 9))):
        cases = sorted(groups[key], key=lambda c: c["cells"])
        scene, variant, extra, amplitude, ppd, method = key
        label = ", ".join(x for x in (scene, variant, extra, "" if amplitude is None else f"A = {amplitude:g}",
                                      f"{ppd} per direction", method) if x)
        print(f"\n{label}")
        columns = cases[0]["columns"]
        head = f"{'cells':>6} {'outcome':<34} {'wall [s]':>9} {'forcing':>8} {'steps':>6}"
        head += "".join(f" {n + ' t=' + format(t, 'g'):>22} {'order':>9}" for n, t in columns)
        print(head)
        previous = None
        for c in cases:
            outcome = "completed" if c["status"] == "completed" else f"failed t={c['failure_time']:.3f} ({c['reason']})"
            forcing = c["forcing"] / c["wall"] if c["wall"] > 0 else float("nan")
            row = f"{c['cells']:>6} {outcome:<34} {c['wall']:>9.3g} {forcing:>7.0%} {c['steps']:>6}"
            for col in columns:
                row += f" {c['values'].get(col, float('nan')):>22.3e} {order_cell(previous, c, col)}"
            print(row)
            previous = c
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
