"""The HTML of a report page: style, rounded tables with units, embedded images and the
interactive (plotly) figures, plotly.js bundled once in the page so that it works offline.

Used by :mod:`mechdyn.results.report`; nothing here knows about mechanisms.
"""

from __future__ import annotations

import base64
import html
import math
import tempfile
from datetime import datetime
from pathlib import Path

import numpy as np

from .._version import __version__
from .table import output_path, written

__all__ = ["esc", "fmt", "cleaned", "heading", "table", "join", "img", "figure_html",
           "side_by_side", "status_html", "write_page", "note"]

CSS = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 2em auto;
       max-width: 84em; color: #222; line-height: 1.4; padding: 0 1em; }
h1 { border-bottom: 2px solid #2c5d8f; padding-bottom: .2em; }
h2 { color: #2c5d8f; margin-top: 1.8em; border-bottom: 1px solid #ccd; }
h3 { margin-bottom: .3em; }
table { border-collapse: collapse; margin: .4em 0 1em 0; font-size: .9em; }
th, td { border: 1px solid #ccd; padding: .25em .6em; text-align: right; }
th { background: #eef2f7; }
td:first-child, th:first-child { text-align: left; }
td.text { text-align: left; }
.note { color: #555; font-size: .9em; }
.status-ok { color: #1a7f37; font-weight: bold; }
.status-bad { color: #b42318; font-weight: bold; }
img { max-width: 100%; border: 1px solid #ddd; margin: .5em 0; }
code { background: #f3f3f3; padding: 0 .25em; }
.row { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; }
.row > .plot { flex: 3 1 36em; min-width: 0; order: 1; }
.row > .aside { flex: 1 1 18em; max-width: 30em; order: 2; }
.figure { border: 1px solid #e3e6ea; margin: .5em 0; }
"""


# ------------------------------------------------------------------ text
def esc(text) -> str:
    """``text`` escaped for HTML."""
    return html.escape(str(text))


def note(text: str) -> str:
    """A small grey paragraph (``text`` is HTML)."""
    return f'<p class="note">{text}</p>'


def fmt(value, sig: int = 4) -> str:
    """A number rounded to ``sig`` significant digits, in fixed notation from 1e-3 to 1e6.

    Examples
    --------
    Trailing zeros are dropped.

    >>> [fmt(v) for v in (0.0, 123.456, -0.0123456, 98765.4, 1.5e-5, 2.0, float("nan"))]
    ['0', '123.5', '-0.01235', '98765', '1.5e-05', '2', '']
    """
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    v = float(value)
    if not math.isfinite(v):
        return "" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    if v == 0.0:
        return "0"
    mag = math.floor(math.log10(abs(v)))
    if -3 <= mag < 6:
        text = f"{v:.{max(0, sig - 1 - mag)}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        return "0" if float(text) == 0.0 else text
    mant, _, exp = f"{v:.{sig - 1}e}".partition("e")
    return f"{mant.rstrip('0').rstrip('.') if '.' in mant else mant}e{exp}"


def cleaned(values, ref=None, rel: float = 1e-9):
    """``values`` (an array) with round-off noise set to zero: entries smaller than ``rel``
    times ``ref`` (default the largest absolute entry).

    Examples
    --------
    >>> cleaned(np.array([3.0, 2e-13, -1.0])).tolist()
    [3.0, 0.0, -1.0]
    """
    v = np.asarray(values, float).copy()
    scale = float(np.nanmax(np.abs(v))) if ref is None and v.size and np.isfinite(v).any() \
        else float(ref or 0.0)
    v[np.abs(v) < rel * scale] = 0.0
    return v


#: column-name unit suffixes (docs/notation.md) and how a heading shows them
_SUFFIXES = (("_kg_m2", "kg m²"), ("_rad_s2", "rad/s²"), ("_rad_s", "rad/s"),
             ("_m_s2", "m/s²"), ("_m_s", "m/s"), ("_kNm", "kN m"), ("_Nm", "N m"),
             ("_kN", "kN"), ("_N", "N"), ("_mm", "mm"), ("_deg", "deg"), ("_kg", "kg"),
             ("_Hz", "Hz"), ("_kW", "kW"), ("_W", "W"), ("_J", "J"), ("_ms", "ms"),
             ("_rpm", "rpm"), ("_s", "s"), ("_m", "m"))
_NAMES = {"J_c_kg_m2": "J_C (kg m²)", "t_s": "t (s)"}


def heading(column: str) -> str:
    """A column name with a unit suffix as a heading: ``"com_x_mm"`` -> ``"com x (mm)"``.

    Examples
    --------
    >>> heading("mass_kg"), heading("energy_lost_J"), heading("body")
    ('mass (kg)', 'energy lost (J)', 'body')
    """
    if column in _NAMES:
        return _NAMES[column]
    for suffix, unit in _SUFFIXES:
        if column.endswith(suffix) and len(column) > len(suffix):
            return f"{column[:-len(suffix)].replace('_', ' ')} ({unit})"
    return column


def table(title: str | None, rows, *, sig: int = 4, headings: bool = True) -> str:
    """A heading (if any) and rows (a list of dicts, or a DataFrame) as an HTML table, numbers
    rounded to ``sig`` significant digits; "" without rows.  Column names with a unit
    suffix become headings with the unit in parentheses (``headings``)."""
    if hasattr(rows, "to_dict"):
        rows = rows.to_dict("records")
    rows = list(rows)
    if not rows:
        return ""
    cols: list[str] = []
    for r in rows:
        cols += [c for c in r if c not in cols]
    head = f"<h3>{esc(title)}</h3>\n" if title else ""
    th = "".join(f"<th>{esc(heading(c) if headings else c)}</th>" for c in cols)
    body = []
    for r in rows:
        cells = []
        for c in cols:
            v = r.get(c)
            cls = ' class="text"' if isinstance(v, str) and cells else ""
            cells.append(f"<td{cls}>{esc(fmt(v, sig))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return (head + '<table class="data">\n<thead><tr>' + th + "</tr></thead>\n<tbody>\n"
            + "\n".join(body) + "\n</tbody>\n</table>")


def join(parts) -> str:
    """The non-empty parts, one per line."""
    return "\n".join(p for p in parts if p)


def status_html(status: str, ok: bool, message: str = "") -> str:
    cls = "status-ok" if ok else "status-bad"
    msg = f" &mdash; {esc(message)}" if message else ""
    return f'<p>Status: <span class="{cls}">{esc(status)}</span>{msg}</p>'


# ------------------------------------------------------------------ images and figures
def img(draw, alt: str, kind: str = "png") -> str:
    """An embedded image drawn by ``draw(path)`` into a temporary ``.png`` or ``.gif``."""
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / f"image.{kind}"
        draw(p)
        b64 = base64.b64encode(p.read_bytes()).decode("ascii")
    return f'<img alt="{esc(alt)}" src="data:image/{kind};base64,{b64}">'


_CONFIG = {"displaylogo": False, "responsive": True,
           "toImageButtonOptions": {"format": "png", "scale": 2}}


def figure_html(fig, div_id: str) -> str:
    """A plotly figure as a ``<div>`` and its script (plotly.js is in the page once, see
    :func:`write_page`)."""
    import plotly.io as pio

    return ('<div class="figure">' + pio.to_html(fig, include_plotlyjs=False, full_html=False,
                                                 div_id=div_id, config=_CONFIG) + "</div>")


def side_by_side(main: str, aside: str) -> str:
    """Two blocks in a row (a figure and the animation beside it), stacked on a narrow
    screen."""
    if not aside:
        return main
    # the aside comes first in the page so that the row has its final layout when the
    # figure's script sizes the plot; CSS puts it on the right
    return (f'<div class="row">\n<div class="aside">{aside}</div>\n'
            f'<div class="plot">{main}</div>\n</div>')


def _plotlyjs() -> str:
    from plotly.offline import get_plotlyjs

    return get_plotlyjs()


def write_page(path, title: str, sections: list[str]) -> Path:
    """Write the HTML page of ``sections`` under ``title``; plotly.js is embedded once
    (in ``<head>``) when a section has a figure."""
    stamp = datetime.now().strftime("%Y-%m-%d %H:%M")
    body = "\n".join(sections)
    script = (f'<script type="text/javascript">{_plotlyjs()}</script>\n'
              if 'class="plotly-graph-div"' in body else "")
    path = output_path(path)
    with written(path) as tmp:
        tmp.write_text(
            f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{esc(title)}</title>\n<style>{CSS}</style>\n{script}</head>\n<body>\n"
            f"<h1>{esc(title)}</h1>\n"
            f"<p class=\"note\">mechdyn {__version__}, {stamp}. Lengths in mm, angles in "
            f"degrees (counter-clockwise positive), forces in kN and N, torques in N m, unless a "
            f"heading says otherwise; joint reactions are the force on the child body from the "
            f"parent at the joint point, ground frame. The plots are interactive: drag to zoom, "
            f"double-click to reset, click a legend entry to hide it.</p>\n"
            + body + "\n</body>\n</html>\n", encoding="utf-8")
    return path
