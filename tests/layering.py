"""The include graph of the C++ tree runs with the flow (README, "What is
inside"): the solver, the manufactured and the exact solutions know nothing of
the application; in tools/app/ the shared pieces (config, fault, json,
toml_file) know no scene, a scene's generic layer (scene/) names no scene and
no suite, each scene (scenes/) knows no suite, and nothing includes a command
(run_case, mms_command, material_drive) but the command line. No header reaches itself.

    /usr/bin/python3 tests/layering.py ROOT   (ctest runs it; exit 1 names each breach)
"""
import re
import sys
from pathlib import Path

ROOT = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parents[1])
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)

# Layer of a file (relative path) -> the layers it must not include.
LAYERS = [
    ("solver/", "low"), ("mms/", "low"), ("analytic/", "low"),
    ("tools/app/scene/", "scene"), ("tools/app/scenes/", "scenes"), ("tools/app/suite/", "suite"),
    ("tools/app/run_case", "command"), ("tools/app/mms_command", "command"), ("tools/app/material_drive", "command"),
    ("tools/app/", "shared"), ("tools/cli/", "cli"), ("tools/bench/", "cli"), ("tools/lib/", "cli"), ("tests/", "cli"),
]
FORBIDDEN = {
    "low": {"shared", "scene", "scenes", "suite", "command", "cli"},
    "shared": {"scene", "scenes", "suite", "command", "cli"},
    "scene": {"scenes", "suite", "command", "cli"},
    "scenes": {"suite", "command", "cli"},
    "suite": {"scenes", "command", "cli"},
    "command": {"scenes", "cli"},
    "cli": set(),
}


def layer(relative):
    return next((name for prefix, name in LAYERS if relative.startswith(prefix)), None)


def resolve(including, target):
    """The repository path an include names: relative to the including file, else to the root."""
    for candidate in (including.parent / target, ROOT / target):
        if candidate.is_file():
            return candidate.resolve().relative_to(ROOT.resolve()).as_posix()
    return None  # a generated or system header


def main():
    sources = [p for d in ("solver", "mms", "analytic", "tools", "tests") for p in (ROOT / d).rglob("*")
               if p.suffix in (".hpp", ".cpp", ".h") and "build" not in p.parts]
    graph, breaches = {}, []
    for path in sources:
        relative = path.resolve().relative_to(ROOT.resolve()).as_posix()
        here = layer(relative)
        graph[relative] = []
        for target in INCLUDE.findall(path.read_text(errors="replace")):
            included = resolve(path, target)
            if included is None:
                continue
            graph[relative].append(included)
            there = layer(included)
            if here in FORBIDDEN and there in FORBIDDEN[here]:
                breaches.append(f"{relative} ({here}) includes {included} ({there})")
    # A cycle among headers: depth-first search from each.
    state = {}

    def visit(node, trail):
        state[node] = "open"
        for nxt in graph.get(node, []):
            if state.get(nxt) == "open":
                breaches.append("include cycle: " + " -> ".join(trail[trail.index(nxt):] + [nxt]))
            elif nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = "done"

    for node in graph:
        if node not in state:
            visit(node, [node])
    for b in breaches:
        print(b)
    print(f"{len(sources)} files, {sum(map(len, graph.values()))} includes, {len(breaches)} against the flow or in a cycle")
    return 1 if breaches or len(sources) < 100 else 0


if __name__ == "__main__":
    sys.exit(main())
