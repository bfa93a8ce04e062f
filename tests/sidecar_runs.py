"""The two runs the sidecar tests read (xdmf_sidecar.py, paraview_sidecar.py):
the ring on 32 cells to t = 0.2 s with four output times, with
particle_fields = "outputs" ("series": a grid per output time) and without
("end": one grid at the end time)."""
import subprocess
import sys
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[1]
TIMES = [0.05, 0.1, 0.15, 0.2]


def sidecar_runs(mpmvv, directory):
    """Yields (name, results file) for each run, its .xmf beside it; exits
    naming the run that failed."""
    for name, extra in (("series", ["--set", "particle_fields=outputs"]), ("end", [])):
        out = Path(directory) / f"{name}.h5"
        ran = subprocess.run([mpmvv, "run", SOURCE / "suites" / "scenes" / "ring.toml", "--set", "cells=32",
                              "--set", f"end_time={TIMES[-1]}", "--set", f"output_times=[{','.join(map(str, TIMES))}]",
                              *extra, "--threads", "1", "--quiet", "-o", out], capture_output=True, text=True)
        if ran.returncode != 0 or not out.with_suffix(".xmf").is_file():
            sys.exit(f"mpmvv run {name}: exit {ran.returncode}, {ran.stderr}")
        yield name, out
