"""A corpus of bad input to the built `mpmvv`: every key of every shipped scene
given a value of the wrong kind and one outside its range, and the files,
suites and options listed in CORPUS. Each must be refused with exit 2 and one
line on stderr that names the key (or file, or option), within TIMEOUT
seconds, with no traceback and no results file left. An external program
whose output is bad (EXTERNAL) is a case that ran: exit 1, its results file
kept with status "failed", and the one FAILED line names the file or what
was wrong.

Usage: bad_input_corpus.py MPMVV_BINARY
"""
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py

SOURCE = Path(__file__).resolve().parent.parent
SCENES = SOURCE / "suites" / "scenes"
TIMEOUT = 30   # seconds: no bad input may make mpmvv wait


def describe(mpmvv, scene):
    """(key, domain text) for every key of `scene` (mpmvv run SCENE --describe)."""
    text = subprocess.run([mpmvv, "run", str(scene), "--describe"], capture_output=True, text=True,
                          timeout=TIMEOUT).stdout
    keys, key = [], None
    for line in text.splitlines():
        match = re.match(r"^(\w+) = ", line)
        if match:
            key = match.group(1)
        elif key and line.startswith("    # "):
            keys.append((key, line))
            key = None
    return keys


def bad_values(domain):
    """Values of the wrong kind and out of range for a key whose description ends in `domain`."""
    if "one of " in domain:
        return ["not-a-choice"]
    numeric = re.search(r"an? (number|integer) in ([\[(])([-\d.e+]+), ([-\d.e+]+)([\])])", domain)
    if numeric:
        upper = float(numeric.group(4))
        return ["abc", "nan", repr(upper * 10 + 10)]
    if re.search(r"an? (number|integer) >=? ", domain):
        return ["abc", "nan", "-1e300"]
    if "list" in domain or "array" in domain:
        return ["abc"]
    return []


def generated(mpmvv):
    for scene in sorted(SCENES.glob("*.toml")):
        for key, domain in describe(mpmvv, scene):
            for value in bad_values(domain):
                yield (f"{scene.name}: {key} = {value}", ["run", str(scene), "--set", f"{key}={value}", "-q"],
                       {}, f"'{key}'")


# (what, arguments, files to write first {name: text or FIFO/LOOP}, what stderr must name)
FIFO, LOOP = object(), object()
RING = str(SCENES / "ring.toml")
STUDY = f'[[study]]\nname = "a"\nscene = "{RING}"\n'
CORPUS = [
    ("scene: a FIFO", ["run", "{d}/f.toml"], {"f.toml": FIFO}, "not a regular file"),
    ("scene: a symlink loop", ["run", "{d}/l.toml"], {"l.toml": LOOP}, "cannot read this scene file"),
    ("scene: a directory", ["run", "{d}"], {}, "not a regular file"),
    ("scene: absent", ["run", "{d}/absent.toml"], {}, "no such scene file"),
    ("scene: not TOML", ["run", "{d}/s.toml"], {"s.toml": "scene = \n"}, "TOML syntax error"),
    ("scene: no scene key", ["run", "{d}/s.toml"], {"s.toml": "cells = 4\n"}, "missing key 'scene'"),
    ("scene: scene = 5", ["run", "{d}/s.toml"], {"s.toml": "scene = 5\n"}, "s.toml:1: 'scene' must be the name"),
    ("scene: unknown scene", ["run", "{d}/s.toml"], {"s.toml": 'scene = "nope"\n'}, "nope"),
    ("scene: binary bytes", ["run", "{d}/s.toml"], {"s.toml": "\x00\x01\x02"}, "s.toml"),
    ("scene: unknown key in file", ["run", "{d}/s.toml"], {"s.toml": 'scene = "ring"\nnokey = 1\n'}, "'nokey'"),
    ("run: --set without =", ["run", RING, "--set", "cells"], {}, "cells"),
    ("run: --set unknown key", ["run", RING, "--set", "nokey=1"], {}, "'nokey'"),
    ("run: -o not .h5", ["run", RING, "-o", "{d}/x.txt"], {}, ".h5"),
    ("run: -o a directory", ["run", RING, "-o", "{d}/dir.h5"], {"dir.h5/keep": "x"}, "is a directory"),
    ("run: -o name too long", ["run", RING, "-o", "{d}/" + "x" * 300 + ".h5"], {}, "File name too long"),
    ("run: --pause-at nan", ["run", RING, "--pause-at", "nan"], {}, "--pause-at"),
    ("run: --pause-at -1", ["run", RING, "--pause-at", "-1"], {}, "--pause-at"),
    ("run: --checkpoint-every 0", ["run", RING, "--checkpoint-every", "0"], {}, "--checkpoint-every"),
    ("run: --checkpoint-every inf", ["run", RING, "--checkpoint-every", "inf"], {}, "--checkpoint-every"),
    ("run: --checkpoint-every nan", ["run", RING, "--checkpoint-every", "nan"], {}, "--checkpoint-every"),
    ("run: -t -1", ["run", RING, "-t", "-1"], {}, "--threads"),
    ("run: output_times decreasing", ["run", RING, "--set", "output_times=[0.5, 0.1]"], {}, "'output_times'"),
    ("run: ring narrower than a cell", ["run", RING, "--set", "cells=4"], {}, "'cells'"),
    ("run: domain 1e300", ["run", RING, "--set", "domain=1e300"], {}, "'domain'"),
    ("run: external_names onto another item's own name",
     ["run", RING, "--set", "external_command=true", "--set", "external_names=reference_position=position"], {},
     "'external_names'"),
    ("suite: a FIFO", ["suite", "{d}/f.toml", "--list"], {"f.toml": FIFO}, "not a regular file"),
    ("suite: a symlink loop", ["suite", "{d}/l.toml", "--list"], {"l.toml": LOOP}, "cannot read this suite file"),
    ("suite: absent", ["suite", "{d}/absent.toml", "--list"], {}, "no such suite file"),
    ("suite: unknown top key", ["suite", "{d}/s.toml", "--list"], {"s.toml": "nokey = 1\n" + STUDY}, "'nokey'"),
    ("suite: study without scene", ["suite", "{d}/s.toml", "--list"], {"s.toml": '[[study]]\nname = "a"\n'},
     "needs a scene"),
    ("suite: study name with a slash", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY.replace('"a"', '"a/b"')}, "a/b"),
    ("suite: two studies one name", ["suite", "{d}/s.toml", "--list"], {"s.toml": STUDY + STUDY},
     "a second study named 'a'"),
    ("suite: scene of a study absent", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY.replace(RING, "nope.toml")}, "no such scene file"),
    ("suite: scene of a study a FIFO", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY.replace(RING, "f.toml"), "f.toml": FIFO}, "not a regular file"),
    ("suite: sweep of a string", ["suite", "{d}/s.toml", "--list"], {"s.toml": STUDY + 'sweep = "cells"\n'},
     "sweep"),
    ("suite: sweep of an empty list", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + "sweep = { cells = [] }\n"}, "cells"),
    ("suite: too many cases", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + "sweep = { cells = [" + ", ".join(str(24 + k) for k in range(120)) + "], amplitude = [" +
      ", ".join(f"{0.01 * (k + 1):.2f}" for k in range(100)) + "] }\n"}, "more than the 10000"),
    ("suite: override matching nothing", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + "sweep = { cells = [32, 64] }\n[[study.override]]\nwhere = { cells = 128 }\n"
                        "set = { cfl = 0.2 }\n"}, "matches none of its cases"),
    ("suite: override where of text for a number", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + "sweep = { cells = [32, 64] }\n[[study.override]]\nwhere = { cells = \"32\" }\n"
                        "set = { cfl = 0.2 }\n"}, "'cells' takes a number"),
    ("suite: two overrides set one key of a case", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + "sweep = { cells = [32, 64] }\n[[study.override]]\nwhere = { cells = 32 }\n"
                        "set = { cfl = 0.2 }\n[[study.override]]\nwhere = {}\nset = { cfl = 0.1 }\n"},
     "both set 'cfl'"),
    ("suite: [ci] saying nothing", ["suite", "{d}/s.toml", "--list"], {"s.toml": "[ci]\n" + STUDY},
     "neither 'covers' nor 'skip'"),
    ("suite: timeout inf", ["suite", "{d}/s.toml", "--list"], {"s.toml": "timeout = inf\n" + STUDY}, "'timeout'"),
    ("suite: override without set", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + "[[study.override]]\nwhere = { cells = 64 }\n"}, "needs a 'set'"),
    ("suite: expect unknown study", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + '[[expect]]\nstudy = "b"\nnorm = "L1_theta0"\nmax_error = 1.0\n'}, "no study named 'b'"),
    ("suite: expect unknown norm", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + '[[expect]]\nstudy = "a"\nnorm = "L9"\nmax_error = 1.0\n'}, "no /errors column 'L9'"),
    ("suite: expect time not an output", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + '[[expect]]\nstudy = "a"\nnorm = "L1_theta0"\ntime = 0.33\nmax_error = 1.0\n'},
     "not an output time"),
    ("suite: expect time after the end", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + 'set = { end_time = 0.5 }\n[[expect]]\nstudy = "a"\nnorm = "L1_theta0"\ntime = 0.75\n'
                        'max_error = 1.0\n'}, "after the end time"),
    ("suite: expect where matching nothing", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + '[[expect]]\nstudy = "a"\nwhere = { method = "gimp" }\nnorm = "L1_theta0"\n'
                        'max_error = 1.0\n'}, "matches no case"),
    ("suite: expect refine on amplitude", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + 'sweep = { amplitude = [0.5, 1.0] }\n[[expect]]\nstudy = "a"\nnorm = "L1_theta0"\n'
                        'refine = "amplitude"\norder = 2\ntolerance = 0.1\n'}, "sets no size"),
    ("suite: expect order as text", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + '[[expect]]\nstudy = "a"\nnorm = "L1_theta0"\norder = "two"\ntolerance = 0.1\n'},
     "'order'"),
    ("suite: expect negative tolerance", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + '[[expect]]\nstudy = "a"\nnorm = "L1_theta0"\norder = 2\ntolerance = -0.1\n'},
     "'tolerance'"),
    ("suite: expect tier unknown", ["suite", "{d}/s.toml", "--list"],
     {"s.toml": STUDY + '[[expect]]\ntier = "nightly"\nstudy = "a"\nnorm = "L1_theta0"\nmax_error = 1.0\n'},
     "'tier'"),
    ("suite: --tier unknown", ["suite", RING.replace("scenes/ring.toml", "ring-quick.toml"), "--list", "--tier",
                               "nightly"], {}, "--tier"),
    ("suite: --budget nan", ["suite", RING.replace("scenes/ring.toml", "ring-quick.toml"), "--list", "--budget",
                             "nan"], {}, "--budget"),
    ("suite: --only bad regex", ["suite", RING.replace("scenes/ring.toml", "ring-quick.toml"), "--list", "--only",
                                 "("], {}, "--only"),
    ("suite: -j 0", ["suite", RING.replace("scenes/ring.toml", "ring-quick.toml"), "--list", "-j", "0"], {}, "--jobs"),
    ("gate: not a directory", ["gate", "{d}/absent"], {}, "absent"),
    ("gate: no manifest", ["gate", "{d}"], {}, "manifest.json"),
    ("gate: manifest not JSON", ["gate", "{d}"], {"manifest.json": "{"}, "not valid JSON"),
    ("gate: manifest a FIFO", ["gate", "{d}"], {"manifest.json": FIFO}, "not a regular file"),
    ("gate: manifest without cases", ["gate", "{d}"], {"manifest.json": "{}"}, "'cases'"),
    ("gate: case without id", ["gate", "{d}"], {"manifest.json": '{"cases": [{"study": "a"}]}'}, "'id'"),
    ("gate: expectation order text", ["gate", "{d}"],
     {"manifest.json": '{"cases": [], "expectations": [{"study": "a", "norm": "n", "order": "two", '
                       '"tolerance": 0.1}]}', "suite.toml": STUDY}, "'order' is 'two'"),
    ("gate: tier unknown", ["gate", "{d}"], {"manifest.json": '{"cases": [], "tier": "x"}'}, "'tier'"),
    ("gate: --json an empty name", ["gate", "{d}", "--json", ""], {"manifest.json": '{"cases": []}'}, "--json"),
    ("report: -o an empty name", ["report", "{d}", "-o", ""], {"manifest.json": '{"cases": []}'}, "-o ''"),
    ("report: manifest not JSON", ["report", "{d}", "-o", "{d}/r"], {"manifest.json": "["}, "not valid JSON"),
    ("report: suite.toml not TOML", ["report", "{d}", "-o", "{d}/r"],
     {"manifest.json": '{"cases": []}', "suite.toml": "[["}, "not valid TOML"),
    ("results check: a FIFO", ["results", "check", "{d}/f.h5"], {"f.h5": FIFO}, "not a regular file"),
    ("results check: not HDF5", ["results", "check", "{d}/f.h5"], {"f.h5": "text"}, "not a readable HDF5"),
    ("results check: absent", ["results", "check", "{d}/absent.h5"], {}, "absent.h5"),
    ("mms eval: --time nan", ["mms", "eval", "ring", "--at", "1,0", "--time", "nan"], {}, "--time"),
    ("mms eval: unknown solution", ["mms", "eval", "nope", "--at", "1,0", "--time", "0.5"], {}, "nope"),
    ("mms eval: point outside", ["mms", "eval", "ring", "--at", "5,0", "--time", "0.5"], {}, "outside the body"),
    ("mms check: tolerance nan", ["mms", "check", "ring", "--tolerance", "nan"], {}, "--tolerance"),
    ("cli: an unknown option for a command", ["--nope"], {}, "unknown option '--nope'"),
    ("cli: an unknown command under results", ["results", "nope"], {}, "unknown command 'nope'"),
    ("cli: --budget 0", ["suite", RING.replace("scenes/ring.toml", "ring-quick.toml"), "--list", "--budget", "0"],
     {}, "--budget: must be a positive number, not 0"),
    ("mms eval: --at nan", ["mms", "eval", "ring", "--at", "nan,0", "--time", "0.1"], {}, "mms eval: --at"),
    ("mms eval: --time where the motion overflows", ["mms", "eval", "ring", "--at", "1,0", "--time", "1e308"], {},
     "--time 1e+308"),
    ("material drive: a folder as table", ["material", "drive", "--table", "{d}"], {}, "not a regular file"),
    ("material drive: --rotation inf", ["material", "drive", "--rotation", "inf"], {}, "--rotation"),
    ("run: --resume with --resume-if-same", ["run", RING, "--resume", "--resume-if-same"], {}, "--resume"),
]

# (what, external_format, external_command, what the FAILED line must name):
# programs that fail, hang or write what mpmvv cannot take.
DAMAGE = """import h5py, sys
item = sys.argv[2]
with h5py.File(sys.argv[1], 'r+') as f:
    for g in f['snapshots'].values():
        if item == 'none':
            for name in ('reference_position', 'position', 'reference_volume'):
                del g[name]
            g['reference_position'] = [[0.0, 0.0]][:0]
            g['position'] = [[0.0, 0.0]][:0]
            g['reference_volume'] = [0.0][:0]
            continue
        d = g[item]; a = d[...]; a[3, 0] = float('nan'); d[...] = a
"""
EXTERNAL = [
    ("external: exits 3", "hdf5", "echo broke; exit 3", "exit status 3"),
    ("external: writes nothing", "hdf5", "true", "no output for t = "),
    ("external: hangs", "hdf5", "sleep 100", "external_timeout"),
    ("external: hangs through SIGTERM", "hdf5", "trap '' TERM; sleep 100", "outlived SIGTERM"),
    ("external: output a FIFO", "hdf5", "mkfifo {output}", "not a regular file"),
    ("external: output a symlink loop", "hdf5", "ln -s {output} {output}", "cannot be read"),
    ("external: output a folder", "hdf5", "mkdir {output}", "not a regular file"),
    ("external: output empty", "hdf5", ": > {output}", "x.external.h5"),
    ("external: output text", "hdf5", "echo text > {output}", "x.external.h5"),
    ("external: csv a FIFO", "csv", "mkdir {output}; mkfifo {output}/particles_0.csv", "not a regular file"),
    ("external: csv without a header", "csv", "mkdir {output}; : > {output}/particles_0.csv", "no header line"),
    ("external: csv half a group", "csv", "mkdir {output}; printf 'X,Y,x,V0\\n1,0,1,1\\n' > {output}/particles_0.csv",
     "give all or none"),
    ("external: csv a word for a number", "csv",
     "mkdir {output}; printf 'X,Y,x,y,V0\\n1,0,one,0,1\\n' > {output}/particles_0.csv", "particles_0.csv"),
    ("external: vtk not XML", "vtk", "mkdir {output}; echo '<VTKFile' > {output}/particles_0.vtu", "particles_0.vtu"),
    ("external: vtk two files for one time", "vtk", "mkdir {output}; : > {output}/particles_0.vtu; "
     ": > {output}/particles_0.vtk", "one file per output time"),
    ("external: a position NaN", "hdf5", "{mpmvv} run {scene} -q --set particle_fields=outputs -o {output} && "
     "/usr/bin/python3 {d}/damage.py {output} position", "a particle position is not a number"),
    ("external: a reference position NaN", "hdf5", "{mpmvv} run {scene} -q --set particle_fields=outputs -o {output} && "
     "/usr/bin/python3 {d}/damage.py {output} reference_position", "'reference_position' of particle 3 is nan"),
    ("external: a tracer NaN", "hdf5", "{mpmvv} run {scene} -q --set particle_fields=outputs -o {output} && "
     "/usr/bin/python3 {d}/damage.py {output} tracer_position", "a tracer position (tracer_position) is not a number"),
    ("external: no particles", "hdf5", "{mpmvv} run {scene} -q --set particle_fields=outputs -o {output} && "
     "/usr/bin/python3 {d}/damage.py {output} none", "no particles"),
    ("external: csv a column twice", "csv",
     "mkdir {output}; printf 'X,Y,x,y,V0,x\\n1,0,1,0,1,1\\n' > {output}/particles_0.csv", "names column 'x' twice"),
    ("external: vtk more points declared than held", "vtk",
     "mkdir {output}; printf '# vtk DataFile Version 3.0\\nx\\nASCII\\nDATASET POLYDATA\\nPOINTS 1000000000 double\\n"
     "1 0 0\\n' > {output}/particles_0.vtk", "POINTS 1000000000 in a file of"),
]


def external_entries(directory):
    (directory / "damage.py").write_text(DAMAGE)


def make_files(directory, files):
    for name, text in files.items():
        path = directory / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if text is FIFO:
            os.mkfifo(path)
        elif text is LOOP:
            path.symlink_to(path.name)
        else:
            path.write_text(text)


def bounded_run(command, directory):
    """`command` run in `directory`, its output captured; None when it gives no answer within TIMEOUT."""
    try:
        return subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT, cwd=directory,
                              errors="replace")
    except subprocess.TimeoutExpired:
        return None


def refused_at_load(mpmvv, what, arguments, files, names):
    """The problems of one input that must be refused with exit 2 (empty: refused as it should be)."""
    with tempfile.TemporaryDirectory() as temporary:
        directory = Path(temporary)
        make_files(directory, files)
        command = [mpmvv] + [a.replace("{d}", str(directory)) for a in arguments]
        if command[1] == "run" and "-o" not in command:
            command += ["-o", str(directory / "x.h5")]
        ran = bounded_run(command, directory)
        if ran is None:
            return f"{what}: no answer within {TIMEOUT} s"
        said = ran.stderr.strip()
        problems = []
        if ran.returncode != 2:
            problems.append(f"exit {ran.returncode}, not 2")
        if names not in said:
            problems.append(f"stderr does not name {names!r}")
        if len(said.splitlines()) != 1:
            problems.append(f"{len(said.splitlines())} lines on stderr, not 1")
        if "Traceback" in said or "terminate called" in said:
            problems.append("a crash")
        if (directory / "x.h5").exists():
            problems.append("a results file was written")
        return f"{what}: {'; '.join(problems)}: {said[-300:]}" if problems else ""


def failed_when_run(mpmvv, what, external_format, program, names):
    """The problems of one external program whose case must fail with exit 1 (empty: as it should)."""
    with tempfile.TemporaryDirectory() as temporary:
        directory = Path(temporary)
        external_entries(directory)
        command = [mpmvv, "run", RING, "-q", "--set", "cells=32", "--set", "end_time=0.05", "--set",
                   "external_timeout=2", "--set", f"external_format={external_format}", "--set",
                   "external_command=" + program.replace("{d}", str(directory)), "-o", str(directory / "x.h5")]
        ran = bounded_run(command, directory)
        if ran is None:
            return f"{what}: no answer within {TIMEOUT} s"
        said = (ran.stdout + ran.stderr).strip()
        failed = [line for line in said.splitlines() if "FAILED" in line]
        problems = []
        if ran.returncode != 1:
            problems.append(f"exit {ran.returncode}, not 1")
        if len(failed) != 1 or names not in failed[0]:
            problems.append(f"no one FAILED line naming {names!r}")
        if "Traceback" in said or "terminate called" in said:
            problems.append("a crash")
        if not (directory / "x.h5").is_file():
            problems.append("no results file kept")
        else:
            with h5py.File(directory / "x.h5", "r") as results:
                if results.attrs.get("status") != "failed":
                    problems.append(f"status {results.attrs.get('status')!r}, not 'failed'")
        return f"{what}: {'; '.join(problems)}: {said[-300:]}" if problems else ""


def main(argv):
    mpmvv = argv[1]
    # Each input is a process of its own that mostly waits (to start, on a
    # file, on a time-out): four at once keep two cores busy.
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        runs = [pool.submit(refused_at_load, mpmvv, *entry) for entry in list(generated(mpmvv)) + CORPUS]
        runs += [pool.submit(failed_when_run, mpmvv, *entry) for entry in EXTERNAL]
        failures = [r.result() for r in runs if r.result()]
    print(f"{len(runs)} bad inputs, {len(runs) - len(failures)} refused as they should be")
    for failure in failures:
        print(f"FAIL {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
