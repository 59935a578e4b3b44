"""Looking at results: a result file read back with its units, signals picked by name or glob,
drawn against time (PNG or SVG with matplotlib; one self-contained interactive HTML page with
plotly). Signals that share a unit share a panel; the time axis is in seconds, minutes, hours,
days or years, whichever reads best for the run's span. Used by `Result.plot` and the `plot`
command (system_ssp.tools.plot)."""
from __future__ import annotations

import fnmatch
import json
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..atomic import PathLike, atomic_write
from ..errors import SSPError
from .names import near

Units = Dict[str, Optional[str]]  # {column: unit or None}


def units_path(path: PathLike) -> Path:
    """The units sidecar of a CSV result file: x.csv -> x.units.json."""
    path = Path(path)
    return path.with_name(f"{path.stem}.units.json")

TIME_UNITS = (("yr", 365.25 * 86400.0), ("d", 86400.0), ("h", 3600.0), ("min", 60.0), ("s", 1.0))
FORMATS = (".png", ".svg", ".html")
MAX_PANELS = 8


def read_result(path: PathLike) -> Tuple[Dict[str, np.ndarray], Units]:
    """({column: values}, {column: unit or None}) of a result file (CSV with its units sidecar,
    or Parquet), columns in file order, `time` first."""
    path = Path(path)
    if not path.exists():
        raise SSPError(f"{path}: no such result file")
    if not path.is_file():
        raise SSPError(f"{path}: not a file (expected a result file: .csv or .parquet)")
    try:
        columns, units = _read_parquet(path) if path.suffix.lower() == ".parquet" else _read_csv(path)
    except SSPError:
        raise
    except Exception as exc:  # pyarrow's, csv's, json's and the decoder's errors: all say the file is not one
        raise SSPError(f"{path}: not a result file ({type(exc).__name__}: {str(exc)[:200]})") from None
    if not isinstance(units, dict):
        units = {}
    if "time" not in columns:
        raise SSPError(f"{path}: no `time` column (columns: {', '.join(list(columns)[:8])}...)")
    return columns, {name: units.get(name) for name in columns}


def _read_parquet(path: Path) -> Tuple[Dict[str, np.ndarray], Any]:
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    meta = table.schema.metadata or {}
    units = json.loads(meta.get(b"neighbor-cosim.units", b"{}").decode())
    return {name: table.column(name).to_numpy() for name in table.column_names}, units


def _read_csv(path: Path) -> Tuple[Dict[str, np.ndarray], Any]:
    import csv

    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if not rows or not rows[0]:
        raise SSPError(f"{path}: empty result file")
    header = rows[0]
    bad = next((k for k, row in enumerate(rows[1:], 2) if row and len(row) != len(header)), None)
    if bad is not None:
        raise SSPError(f"{path}:{bad}: {len(rows[bad - 1])} values, the header has {len(header)} columns")
    body = [row for row in rows[1:] if row]
    columns = {}
    for i, name in enumerate(header):
        texts = [row[i] for row in body]
        try:
            columns[name] = np.array([float(x) for x in texts], dtype=float)
        except ValueError as exc:
            if name == "time":
                raise SSPError(f"{path}: not a result file: its time column holds {exc}") from None
            columns[name] = np.array(texts, dtype=object)  # a String variable's column
    sidecar = units_path(path)
    units = json.loads(sidecar.read_text(encoding="utf-8")) if sidecar.is_file() else {}
    return columns, units


def select(names: Sequence[str], patterns: Sequence[str], where: str = "") -> List[str]:
    """The columns matching `patterns` (names or globs), in the file's order; SSPError naming a
    pattern that matches nothing, with the closest names."""
    candidates = [n for n in names if n != "time"]
    if not patterns:
        return candidates
    chosen = []
    for pattern in patterns:
        hits = [n for n in candidates if fnmatch.fnmatchcase(n, pattern)] if any(
            c in pattern for c in "*?[") else [n for n in candidates if n == pattern]
        if not hits:
            raise SSPError(f"{where}signal {pattern!r}: no such column{near(pattern, candidates)} (globs like "
                           "'dynamics.q_BN*' match several; [[] matches a bracket)")
        chosen += [h for h in hits if h not in chosen]
    return [n for n in candidates if n in chosen]


def drawable(columns: Any, names: Sequence[str]) -> List[str]:
    """The `names` whose columns hold numbers: a text column (a String variable) has no axis."""
    return [n for n in names if np.asarray(columns[n]).dtype.kind in "biuf"]


def default_signals(names: Sequence[str], units: Units) -> Tuple[List[str], str]:
    """Every signal when none is named, as many units' worth as fit (the first MAX_PANELS units
    in column order); the second item says what was left out ("" if nothing)."""
    signals = [n for n in names if n != "time"]
    groups = panels(signals, units)
    if len(groups) <= MAX_PANELS:
        return signals, ""
    kept = [s for _, group in groups[:MAX_PANELS] for s in group]
    return kept, (f"drew the {len(kept)} signals of the first {MAX_PANELS} units of {len(groups)}; name signals or "
                  "globs to draw others")


def time_axis(t: np.ndarray) -> Tuple[np.ndarray, str]:
    """The time column in the unit that reads best for its span (years for a mission)."""
    span = float(t[-1] - t[0]) if len(t) else 0.0
    for unit, seconds in TIME_UNITS:
        if span >= 2 * seconds or unit == "s":
            return t / seconds, unit
    return t, "s"  # pragma: no cover


def panels(signals: Sequence[str], units: Units) -> List[Tuple[Optional[str], List[str]]]:
    """[(unit, [signals])]: signals that share a unit share a panel, in first-seen order."""
    groups: Dict[Optional[str], List[str]] = {}
    for s in signals:
        groups.setdefault(units.get(s), []).append(s)
    return list(groups.items())


def plot(columns: Dict[str, np.ndarray], units: Units, signals: Sequence[str], out: PathLike,
         title: str = "") -> Path:
    """Draw `signals` against time into `out` (.png, .svg or .html); returns the path."""
    out = Path(out)
    if out.suffix.lower() not in FORMATS:
        raise SSPError(f"--out {out}: unknown format {out.suffix!r} (expected {', '.join(FORMATS)})")
    title = "".join(c if c.isprintable() else " " for c in title)  # no font draws a NUL or a line break
    if not signals:
        raise SSPError("nothing to plot: the result has no signal but time")
    texts = [n for n in signals if n not in drawable(columns, signals)]
    if texts:
        raise SSPError(f"signal {texts[0]!r} holds text (a String variable): it has no axis to be drawn on")
    groups = panels(signals, units)
    if len(groups) > MAX_PANELS:
        raise SSPError(f"{len(signals)} signals in {len(groups)} different units: choose at most {MAX_PANELS} units' "
                       "worth (name the signals or a glob)")
    if out.suffix.lower() == ".html":
        return _plot_html(columns, units, signals, out, title)
    t, t_unit = time_axis(np.asarray(columns["time"], dtype=float))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(groups), 1, figsize=(10, 2.6 * len(groups) + 0.8), sharex=True, squeeze=False)
    for ax, (unit, names) in zip(axes[:, 0], groups):
        for name in names:
            ax.plot(t, np.asarray(columns[name], dtype=float), label=name, linewidth=1.2)
        ax.set_ylabel(unit or "(no unit)")
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8, ncol=1 if len(names) < 5 else 2)
        ax.ticklabel_format(axis="y", useOffset=False)
    axes[-1, 0].set_xlabel(f"time ({t_unit})")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - (0.35 / fig.get_figheight() if title else 0.0)))
    with atomic_write(out, "wb") as f:
        fig.savefig(f, format=out.suffix.lower()[1:], dpi=110)
    plt.close(fig)
    return out


Band = Tuple[float, float, str]  # (start, end, label) in seconds: a shaded span (a mode)


def interactive_figure(columns: Dict[str, np.ndarray], units: Units, signals: Sequence[str], title: str = "",
                       bands: Sequence[Band] = ()) -> Any:
    """A plotly figure of `signals` against time: a panel per unit, pan and zoom, `bands` shaded
    and labelled (e.g. the mission's modes). SSPError without plotly."""
    try:
        import plotly.graph_objects as go
        from plotly.subplots import make_subplots
    except ImportError:
        raise SSPError("an interactive (HTML) plot needs plotly (pip install plotly)") from None
    groups = panels(signals, units)
    t, t_unit = time_axis(np.asarray(columns["time"], dtype=float))
    scale = float(columns["time"][-1]) / float(t[-1]) if len(t) and t[-1] else 1.0
    fig = make_subplots(rows=len(groups), cols=1, shared_xaxes=True, vertical_spacing=0.04)
    # SVG traces draw everywhere (no WebGL, which a browser without a GPU only emulates, with
    # console warnings); WebGL only where SVG would be slow
    trace = go.Scatter if len(t) <= WEBGL_ABOVE else go.Scattergl
    for row, (unit, names) in enumerate(groups, 1):
        for name in names:
            fig.add_trace(trace(x=t, y=np.asarray(columns[name], dtype=float), name=name, mode="lines"),
                          row=row, col=1)
        fig.update_yaxes(title_text=unit or "(no unit)", row=row, col=1)
    for k, (t0, t1, label) in enumerate(bands):
        fig.add_vrect(x0=t0 / scale, x1=t1 / scale, fillcolor=BAND_COLORS[k % len(BAND_COLORS)], opacity=0.12,
                      line_width=0, annotation_text=label, annotation_position="top left",
                      annotation_font_size=9, row="all", col=1)
    fig.update_xaxes(title_text=f"time ({t_unit})", row=len(groups), col=1)
    fig.update_layout(title=title, height=260 * len(groups) + 120, template="plotly_white")
    return fig


WEBGL_ABOVE = 50_000  # points per signal
BAND_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")


def _plot_html(columns: Dict[str, np.ndarray], units: Units, signals: Sequence[str], out: Path,
               title: str) -> Path:
    fig = interactive_figure(columns, units, signals, title)
    html = fig.to_html(include_plotlyjs=True, full_html=True)  # one file, no network to open it
    with atomic_write(out, "w", encoding="utf-8") as f:
        f.write(html)
    return out
