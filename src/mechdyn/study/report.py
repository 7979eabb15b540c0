"""The study section of an HTML report: counts by status, the range of every figure,
the best variants, the failed ones, and the scatter and Pareto plots embedded."""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from ..results.report_html import img
from .plots import axis_label, plot_pareto, plot_scatter

__all__ = ["study_section", "write_study_report"]

_META = ("variant", "status", "message", "evaluated", "seconds", "objective", "feasible")
_OK = ("success", "redundant")


def _html_table(df) -> str:
    return df.to_html(index=False, border=0, na_rep="", float_format=lambda v: f"{v:.6g}")


def study_section(table, parameters: list[str], *, figure: str | None = None,
                  pareto: tuple[str, str] | None = None, best: int = 5) -> str:
    """An HTML fragment (``<h2>`` and what follows) that reports a study table.

    Parameters
    ----------
    table : pandas.DataFrame
        A study table (:func:`~mechdyn.study.execute.run_study`).
    parameters : list of str
        Its parameter columns (e.g. ``"bodies.crank.points.A.x_m"``).
    figure : str, optional
        The figure the best variants are chosen by (smallest first) and plotted
        against the first parameter; default the first figure column.
    pareto : (str, str), optional
        Two figures for a Pareto plot.
    best : int
        Number of best variants listed.

    Returns
    -------
    str
        HTML: counts by status, the range of each figure in engineering units, the best
        and the failed variants, the plots.

    Raises
    ------
    ModelError
        A column that is not in the table (from the plots).

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"variant": [0, 1], "r_m": [0.04, 0.05], "M_Nm": [20.0, np.nan],
    ...                    "status": ["success", "assembly-failed"],
    ...                    "message": ["", "the loop does not close"]})
    >>> text = study_section(df, ["r_m"])
    >>> "Design study" in text and "the loop does not close" in text
    True
    """
    import pandas as pd

    figures = [c for c in table if c not in _META and c not in parameters
               and pd.api.types.is_numeric_dtype(table[c])]
    ok = table[table["status"].isin(_OK)]
    counts = table["status"].value_counts()
    parts = [f"<h2>Design study: {len(table)} variants</h2>",
             "<p>" + ", ".join(f"{int(n)} {html.escape(str(s))}" for s, n in counts.items())
             + "</p>"]
    rows = []
    for c in parameters + figures:
        label, factor = axis_label(c)
        v = ok[c].to_numpy(float) * factor if len(ok) else np.array([np.nan])
        rows.append({"quantity": label, "min": np.nanmin(v), "median": np.nanmedian(v),
                     "max": np.nanmax(v), "kind": "parameter" if c in parameters else "figure"})
    parts += ["<h3>Ranges (successful variants)</h3>", _html_table(pd.DataFrame(rows))]
    figure = figure or (figures[0] if figures else None)
    if figure is not None and len(ok):
        top = ok.nsmallest(best, figure)[["variant", *parameters, figure]]
        parts += [f"<h3>Smallest {html.escape(axis_label(figure)[0])}</h3>",
                  _html_table(top)]
        parts.append(img(lambda p: plot_scatter(table, parameters[0], figure, p),
                         f"{figure} over {parameters[0]}"))
    if pareto is not None and len(ok):
        parts.append(img(lambda p: plot_pareto(table, *pareto, p), "Pareto front"))
    failed = table[~table["status"].isin(_OK)]
    if len(failed):
        parts += ["<h3>Failed variants</h3>",
                  _html_table(failed[["variant", *parameters, "status", "message"]])]
    return "\n".join(parts)


def write_study_report(table, path: str | Path, parameters: list[str], *,
                       title: str = "Design study", **kwargs) -> Path:
    """Write a self-contained HTML page with the :func:`study_section` of a table.

    Parameters
    ----------
    table : pandas.DataFrame
    path : str or Path
        The ``.html`` file.
    parameters : list of str
        The parameter columns.
    title : str
    **kwargs
        ``figure``, ``pareto``, ``best`` of :func:`study_section`.

    Returns
    -------
    Path

    Raises
    ------
    ModelError
        A column that is not in the table.

    Examples
    --------
    >>> import pandas as pd, tempfile, pathlib
    >>> df = pd.DataFrame({"variant": [0], "r_m": [0.04], "M_Nm": [20.0],
    ...                    "status": ["success"], "message": [""]})
    >>> out = write_study_report(df, pathlib.Path(tempfile.mkdtemp()) / "s.html", ["r_m"])
    >>> out.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    True
    """
    path = Path(path)
    body = study_section(table, parameters, **kwargs)
    tmp = path.with_name("tmp-" + path.name)
    tmp.write_text(f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                   f"<title>{html.escape(title)}</title>\n</head>\n<body>\n"
                   f"<h1>{html.escape(title)}</h1>\n{body}\n</body>\n</html>\n",
                   encoding="utf-8")
    tmp.replace(path)
    return path
