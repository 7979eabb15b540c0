"""Plots of a study table: a parameter against a figure, and the Pareto front of two
figures, with axes labelled in engineering units (mm, N m, deg ...)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError, did_you_mean
from ..results.figure import figure, save

__all__ = ["axis_label", "pareto_front", "plot_scatter", "plot_pareto"]

#: column suffix -> (unit shown, factor from the column's unit)
_UNITS = {"_kg_m2": ("kg m²", 1.0), "_Nm": ("N m", 1.0), "_m": ("mm", 1e3), "_N": ("N", 1.0),
          "_deg": ("deg", 1.0), "_rpm": ("rpm", 1.0), "_kg": ("kg", 1.0), "_W": ("W", 1.0),
          "_J": ("J", 1.0), "_s": ("s", 1.0), "_rad_s": ("rad/s", 1.0), "_m_s": ("m/s", 1.0),
          "_m_s2": ("m/s²", 1.0)}
_OK = ("success", "redundant")


def axis_label(column: str) -> tuple[str, float]:
    """The axis label of a table column and the factor to its shown unit.

    Examples
    --------
    >>> axis_label("bodies.crank.points.A.x_m")
    ('bodies.crank.points.A.x [mm]', 1000.0)
    >>> axis_label("M_drive_phi_peak_Nm")
    ('M_drive_phi_peak [N m]', 1.0)
    >>> axis_label("v_ram_peak_m_s")  # the longest suffix: m/s, not "_s" after "v_ram_peak_m"
    ('v_ram_peak [m/s]', 1.0)
    >>> axis_label("drives.motor.gear_ratio")
    ('drives.motor.gear_ratio [-]', 1.0)
    """
    for suffix, (unit, factor) in sorted(_UNITS.items(), key=lambda kv: -len(kv[0])):
        if column.endswith(suffix):
            return f"{column[:-len(suffix)]} [{unit}]", factor
    return f"{column} [-]", 1.0


def _columns(df, *names):
    for n in names:
        if n not in df:
            raise ModelError(f"study plot: {did_you_mean(n, list(df.columns), 'column')}")


def pareto_front(df, objectives: list[str]) -> np.ndarray:
    """Rows of a study table that no other successful row beats in every objective
    (all minimised; failed rows are never on the front).

    Parameters
    ----------
    df : pandas.DataFrame
    objectives : list of str
        Columns to minimise.

    Returns
    -------
    ndarray of bool, shape (len(df),)

    Raises
    ------
    ModelError
        An unknown column (the columns are listed).

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"a": [1, 2, 3, 2], "b": [3, 1, 2, 2], "status": ["success"] * 4})
    >>> pareto_front(df, ["a", "b"]).tolist()
    [True, True, False, False]
    """
    _columns(df, *objectives)
    y = df[list(objectives)].to_numpy(float)
    ok = np.isfinite(y).all(axis=1)
    if "status" in df:
        ok &= df["status"].isin(_OK).to_numpy()
    front = ok.copy()
    for i in np.flatnonzero(ok):
        others = y[ok]
        beaten = np.all(others <= y[i], axis=1) & np.any(others < y[i], axis=1)
        front[i] = not beaten.any()
    return front


def plot_scatter(df, x: str, y: str, path: str | Path | None = None, *,
                 color: str | None = None, title: str | None = None, dpi: int = 120):
    """A parameter (or figure) against a figure, one dot per successful variant, the
    failed variants marked on the x axis.

    Parameters
    ----------
    df : pandas.DataFrame
        A study table.
    x, y : str
        Columns.
    path : str or Path, optional
        Write the plot there (.png, .pdf, .svg); otherwise return the figure.
    color : str, optional
        A column that colours the dots.

    Returns
    -------
    Path or matplotlib.figure.Figure

    Raises
    ------
    ModelError
        An unknown column.

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"r_m": [0.04, 0.05], "M_Nm": [20.0, 25.0],
    ...                    "status": ["success", "success"]})
    >>> plot_scatter(df, "r_m", "M_Nm").axes[0].get_xlabel()
    'r [mm]'
    """
    _columns(df, x, y, *([color] if color else []))
    fig, (ax,) = figure(1, width=6.0, height=4.5)
    (xl, fx), (yl, fy) = axis_label(x), axis_label(y)
    ok = df["status"].isin(_OK).to_numpy() if "status" in df else np.ones(len(df), bool)
    kw = {}
    if color:
        cl, fc = axis_label(color)
        kw = {"c": df[color].to_numpy(float)[ok] * fc, "cmap": "viridis"}
    sc = ax.scatter(df[x].to_numpy(float)[ok] * fx, df[y].to_numpy(float)[ok] * fy, s=12, **kw)
    if color:
        fig.colorbar(sc, ax=ax, label=cl)
    if (~ok).any():
        ax.plot(df[x].to_numpy(float)[~ok] * fx, np.zeros((~ok).sum()), "rx",
                transform=ax.get_xaxis_transform(), clip_on=False,
                label=f"{int((~ok).sum())} failed variants")
        ax.legend(loc="best")
    ax.set_xlabel(xl)
    ax.set_ylabel(yl)
    ax.set_title(title or f"{yl} over {xl}")
    return fig if path is None else save(fig, path, dpi)


def plot_pareto(df, x: str, y: str, path: str | Path | None = None, *,
                title: str | None = None, dpi: int = 120):
    """Two figures (both minimised) of every successful variant, the Pareto front
    highlighted and joined.

    Parameters
    ----------
    df : pandas.DataFrame
        A study table.
    x : str
        The first objective column (horizontal axis).
    y : str
        The second objective column (vertical axis).
    path : str or Path, optional
        Write the plot there; otherwise return the figure.
    title : str, optional
    dpi : int

    Returns
    -------
    Path or matplotlib.figure.Figure
        The path written, or the figure when no path is given.

    Raises
    ------
    ModelError
        An unknown column (the table's columns are listed).

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"F_N": [1.0, 2.0, 3.0], "M_Nm": [3.0, 1.0, 2.0]})
    >>> plot_pareto(df, "F_N", "M_Nm").axes[0].get_ylabel()
    'M [N m]'
    """
    front = pareto_front(df, [x, y])
    fig, (ax,) = figure(1, width=6.0, height=4.5)
    (xl, fx), (yl, fy) = axis_label(x), axis_label(y)
    ok = df["status"].isin(_OK).to_numpy() if "status" in df else np.ones(len(df), bool)
    X, Y = df[x].to_numpy(float) * fx, df[y].to_numpy(float) * fy
    ax.scatter(X[ok & ~front], Y[ok & ~front], s=10, color="0.6", label="variants")
    order = np.argsort(X[front])
    ax.plot(X[front][order], Y[front][order], "o-", color="C3", ms=5,
            label=f"Pareto front ({int(front.sum())})")
    ax.set_xlabel(xl)
    ax.set_ylabel(yl)
    ax.legend(loc="best")
    ax.set_title(title or "Pareto front")
    return fig if path is None else save(fig, path, dpi)
