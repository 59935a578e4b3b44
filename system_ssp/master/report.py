"""A self-contained HTML report: one file that opens in any browser without network access
(plotly.js is inside it once): a title, sections of tables and text, interactive figures (pan,
zoom, a panel per unit, shaded mode bands), the run's settings and the software versions.

`run_report` is the report of any run (`neighbor-cosim run ... --report x.html`); applications
compose their own from `page`, `markdown`, `table` and `figure` (the mission's report.html).
"""
from __future__ import annotations

from html import escape
import platform
import re
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import fmpy
import numpy as np

from ..version import __version__
from .plotting import Band, default_signals, drawable, interactive_figure, select

STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1200px; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.15em; margin-top: 1.6em; border-bottom: 1px solid #ddd; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }
th { background: #f3f5f8; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.far td { background: #fff3e0; } p.note { color: #555; font-size: 0.9em; }
"""


def page(title: str, sections: Sequence[Tuple[str, str]]) -> str:
    """The whole HTML document: `sections` are (heading, HTML body) pairs."""
    import plotly.offline

    body = "\n".join(f"<h2>{escape(h)}</h2>\n{html}" for h, html in sections)
    return (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{escape(title)}</title>\n"
            f"<style>{STYLE}</style>\n<script type=\"text/javascript\">{plotly.offline.get_plotlyjs()}</script>\n"
            f"</head><body>\n<h1>{escape(title)}</h1>\n{body}\n</body></html>\n")


def table(header: Sequence[str], rows: Sequence[Sequence[Any]], far: Sequence[bool] = ()) -> str:
    """An HTML table; numbers right-aligned; rows flagged in `far` shaded."""
    def cell(v: Any) -> str:
        text = escape(str(v))
        return f'<td class="num">{text}</td>' if re.fullmatch(r"[-+]?[\d.,eE+%\s-]+", str(v).strip() or "x") \
            else f"<td>{text}</td>"
    head = "".join(f"<th>{escape(h)}</th>" for h in header)
    shaded = ' class="far"'
    body = "".join(f"<tr{shaded if k < len(far) and far[k] else ''}>{''.join(cell(v) for v in row)}</tr>"
                   for k, row in enumerate(rows))
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def markdown(text: str, far_beyond: Optional[float] = None) -> str:
    """Text with pipe tables (as the applications print them) as HTML: tables as tables, other
    lines as paragraphs. With `far_beyond`, a row whose last cell is a percentage beyond it is
    shaded (a number far from the thesis)."""
    out: List[str] = []
    block: List[str] = []

    def flush() -> None:
        if block:
            cells = [[c.strip() for c in line.strip().strip("|").split("|")] for line in block]
            rows = [r for r in cells[1:] if not all(set(c) <= set("-: ") for c in r)]
            far = [far_beyond is not None and _percent(r[-1]) is not None and abs(_percent(r[-1]) or 0) > far_beyond
                   for r in rows]
            out.append(table(cells[0], rows, far))
            block.clear()

    for line in text.splitlines():
        if line.strip().startswith("|"):
            block.append(line)
            continue
        flush()
        if line.strip():
            out.append(f"<p>{escape(line.strip())}</p>")
    flush()
    return "\n".join(out)


def _percent(text: str) -> Optional[float]:
    m = re.fullmatch(r"\s*([-+]?\d+(?:\.\d+)?)\s*%\s*", text)
    return float(m.group(1)) if m else None


def figure(columns: Mapping[str, np.ndarray], units: Mapping[str, Optional[str]], signals: Sequence[str],
           title: str = "", bands: Sequence[Band] = ()) -> str:
    """An interactive figure's <div> (plotly.js comes with `page`)."""
    fig = interactive_figure(dict(columns), dict(units), signals, title, bands)
    return str(fig.to_html(full_html=False, include_plotlyjs=False))


def histograms(values: Mapping[str, Sequence[float]], units: Optional[Mapping[str, Optional[str]]] = None) -> str:
    """Interactive histograms, one panel per named sample (a campaign's metrics), as a <div>."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    names = list(values)
    cols = min(3, max(1, len(names)))
    rows = -(-len(names) // cols)
    fig = make_subplots(rows=rows, cols=cols, subplot_titles=names)
    for k, name in enumerate(names):
        fig.add_trace(go.Histogram(x=list(values[name]), name=name, showlegend=False), row=k // cols + 1,
                      col=k % cols + 1)
        fig.update_xaxes(title_text=(units or {}).get(name) or "", row=k // cols + 1, col=k % cols + 1)
        fig.update_yaxes(title_text="runs", row=k // cols + 1, col=k % cols + 1)
    fig.update_layout(height=300 * rows + 60, template="plotly_white")
    return str(fig.to_html(full_html=False, include_plotlyjs=False))


def bands(t: np.ndarray, codes: np.ndarray, labels: Mapping[int, str], shortest: float = 0.0) -> List[Band]:
    """Shaded spans of a mode signal: (start, end, label) for each run of equal `codes`; spans
    shorter than `shortest` seconds are folded into the one before (a daily five-second wake
    does not hide a five-year span)."""
    t = np.asarray(t, dtype=float)
    codes = np.asarray(codes)
    if t.size == 0:
        return []
    edges = np.flatnonzero(np.diff(codes) != 0) + 1
    starts, ends = np.concatenate(([0], edges)), np.concatenate((edges, [t.size - 1]))
    out: List[Band] = []
    for a, b in zip(starts, ends):
        label = labels.get(int(codes[a]), str(codes[a]))
        t0, t1 = float(t[a]), float(t[b])
        if out and (t1 - t0 < shortest or out[-1][2] == label):
            out[-1] = (out[-1][0], t1, out[-1][2])
        else:
            out.append((t0, t1, label))
    return out


def versions() -> Dict[str, str]:
    return {"neighbor-cosim": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "fmpy": fmpy.__version__, "platform": platform.platform()}


def run_report(result: Any, title: str, settings: Mapping[str, Any], signals: Sequence[str] = (),
               first: Sequence[Tuple[str, str]] = ()) -> str:
    """The report of one run: outcome, settings, versions and a figure of its recorded signals
    (`signals`: names or globs; none: as many units' worth as fit); `first`: (title, HTML)
    sections before them (the requirements' verdicts)."""
    names = list(result.data.dtype.names or ())
    chosen = select(names, list(signals)) if signals else default_signals(drawable(result.data, names),
                                                                          result.units)[0]
    outcome = [("stop time", f"{result.stop_time:g} s"), ("stop reason", result.stop_reason),
               ("steps", result.steps), ("algorithm", result.algorithm), ("order", " ".join(result.order)),
               ("wall time", f"{result.wall_time:.3f} s")]
    if result.modes:
        outcome += [(f"mode {m}", f"{v['steps']} steps, {v['simulated_time']:g} s simulated")
                    for m, v in result.modes.items()]
    sections = [*first, ("Outcome", table(("quantity", "value"), outcome))]
    if getattr(result, "events", None):
        sections.append(("Events", table(("time (s)", "event", "action", "description"), [
            (f"{e['t']:g}", e["event"], e["action"], e["description"]) for e in result.events])))
    if chosen:
        sections.append(("Signals", figure({n: result.data[n] for n in names}, result.units, chosen)))
    sections.append(("Settings", table(("setting", "value"), [(k, v) for k, v in settings.items()])))
    sections.append(("Versions", table(("software", "version"), list(versions().items()))))
    return page(title, sections)
