"""What the figures of a report (report.py) share: a figure's entry (its
study, file and caption), the two halves of a refinement series' label, a
file name's slug, the figure saved under it, a time's text and the order of key values."""
import re
from dataclasses import dataclass
from pathlib import Path

from . import figures
from .report_rows import METHOD_KEYS


@dataclass(frozen=True)
class FigureEntry:
    study: str
    path: Path                   # None for a figure left out (the caption says why)
    caption: str


def split_label(series):
    method = {k: v for k, v in series.label_keys.items() if k in METHOD_KEYS}
    problem = {k: v for k, v in series.label_keys.items() if k not in METHOD_KEYS}
    join = lambda keys: ", ".join(f"{k}={v}" for k, v in keys.items())  # noqa: E731
    return join(method), join(problem)


def slug(*parts):
    return re.sub(r"[^A-Za-z0-9_.=-]+", "_", "-".join(str(p) for p in parts)).strip("_")


# Figures written by saved() in this process (the report's progress counts them).
written = {"figures": 0}


def saved(figure, directory, study, *name):
    """The figure written to DIRECTORY/<study-name>.png (figures.save_png): its path."""
    path = directory / f"{slug(study, *name)}.png"
    figures.save_png(figure, path)
    written["figures"] += 1
    return path


def time_text(t):
    return f"t = {t:g} s"


def sort_value(value):
    return (0, value, "") if isinstance(value, (int, float)) else (1, 0, str(value))
