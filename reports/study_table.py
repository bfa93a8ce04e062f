#!/usr/bin/python3
"""Status and error of ring results files, grouped by amplitude and method:
whether each run completed (or when and why it stopped), its wall time, the
L1 error of eq. 3.1 (000_1dbcb8acb6dddab9.txt) on Theta = 0 at chosen times,
and the observed order between consecutive meshes of the same group.

Usage: /usr/bin/python3 reports/study_table.py [--times 0.25,1.0] RESULTS.h5 ...
"""
import argparse
import math
import sys
from collections import defaultdict

import h5py


def read_case(path, times):
    with h5py.File(path, "r") as f:
        recorded = list(f["errors/time"][:])
        l1 = list(f["errors/L1_theta0"][:])
        values = {}
        for t in times:
            hits = [k for k, r in enumerate(recorded) if abs(r - t) < 1e-9]
            values[t] = l1[hits[0]] if hits else float("nan")
        return {
            "amplitude": float(f.attrs["amplitude"]),
            "method": str(f.attrs["method"]),
            "cells": int(f.attrs["cells"]),
            "h": float(f.attrs["h"]),
            "status": str(f.attrs["status"]),
            "reason": str(f.attrs["failure_reason"]),
            "failure_time": float(f.attrs["failure_time"]),
            "wall": float(f.attrs["wall_time_s"]),
            "steps": int(f.attrs["steps"]),
            "rate": float(f.attrs["particle_steps_per_second"]),
            "l1": values,
        }


def order(coarse, fine):
    a, b = coarse["l1"], fine["l1"]
    return {t: (math.log(a[t] / b[t]) / math.log(coarse["h"] / fine["h"])
                if a[t] > 0 and b[t] > 0 else float("nan")) for t in a}


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--times", default="0.25,1.0", help="output times to tabulate")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args(argv)
    times = [float(t) for t in args.times.split(",")]
    groups = defaultdict(list)
    for path in args.files:
        c = read_case(path, times)
        groups[(c["amplitude"], c["method"])].append(c)
    for key in sorted(groups, key=lambda k: (k[0], ["linear", "gimp", "cpdi"].index(k[1]) if k[1] in ("linear", "gimp", "cpdi") else 9)):
        cases = sorted(groups[key], key=lambda c: c["cells"])
        print(f"\nA = {key[0]:g}, {key[1]}")
        head = f"{'cells':>6} {'outcome':<34} {'wall [s]':>9} {'steps':>6}"
        head += "".join(f" {'L1 t=' + format(t, 'g'):>11} {'order':>6}" for t in times)
        print(head)
        previous = None
        for c in cases:
            outcome = "completed" if c["status"] == "completed" else f"failed t={c['failure_time']:.3f} ({c['reason']})"
            row = f"{c['cells']:>6} {outcome:<34} {c['wall']:>9.3g} {c['steps']:>6}"
            p = order(previous, c) if previous else {}
            for t in times:
                row += f" {c['l1'][t]:>11.3e} {p.get(t, float('nan')):>6.2f}"
            print(row)
            previous = c
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
