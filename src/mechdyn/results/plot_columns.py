"""Plot of chosen table columns of any record, one panel per unit."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import ModelError, did_you_mean
from .figure import figure as _figure
from .figure import save as _save
from .plot_axes import display_unit, force_unit, model_name, speed_text, x_axis
from .table import UNIT_SUFFIXES, unit_of_column

__all__ = ["plot_columns", "table_of", "check_columns"]


def table_of(record):
    """The record's table as written by ``-o`` (a trajectory with its points' columns too)."""
    if type(record).__name__ == "Trajectory":
        return record.to_dataframe(points=True)
    return record.to_dataframe()


def _stem(column: str) -> str:
    """A column's name without its unit suffix (``omega_rod_rad_s`` -> ``omega_rod``)."""
    for suffix in sorted(UNIT_SUFFIXES, key=len, reverse=True):
        if column.endswith(suffix) and len(column) > len(suffix):
            return column[: -len(suffix)]
    return column


def check_columns(columns: Sequence[str], valid, flag: str = "columns") -> list[str]:
    """The column names of ``columns`` (a sequence, or one comma-separated str).

    Raises
    ------
    ModelError
        No column, or unknown ones: the message names them and lists the valid columns
        (:func:`~mechdyn.errors.did_you_mean`).

    Examples
    --------
    >>> check_columns("phi_deg, F_A_N", ["phi_deg", "F_A_N", "t_s"])
    ['phi_deg', 'F_A_N']
    >>> check_columns(["phi_dg"], ["phi_deg", "t_s"], "-c")
    Traceback (most recent call last):
    ...
    mechdyn.errors.ModelError: -c: unknown column 'phi_dg'; valid column names: 'phi_deg', 't_s'
    """
    names = [c.strip() for c in (columns.split(",") if isinstance(columns, str) else columns)]
    names = [c for c in names if c]
    valid = list(valid)
    unknown = [c for c in names if c not in valid]
    if unknown:
        more = f" (also unknown: {', '.join(map(repr, unknown[1:]))})" if unknown[1:] else ""
        raise ModelError(f"{flag}: {did_you_mean(unknown[0], valid, 'column')}{more}")
    if not names:
        raise ModelError(f"{flag}: no columns given; valid column names: "
                         f"{', '.join(map(repr, sorted(valid)))}")
    return names


def plot_columns(record, columns, path=None, *, title: str | None = None, dpi: int = 120):
    """Plot chosen columns of a record's table against the swept coordinate (or the time).

    Columns of one unit share a panel; angles are drawn in deg, lengths in mm, forces in N
    or kN (one unit per panel), other quantities in their SI unit; a full turn of an angle
    runs 0..360 deg.

    Parameters
    ----------
    record : KinematicSweep, Trajectory or Kinetostatics
    columns : sequence of str, or one comma-separated str
        Column names as in the record's table (``phi_deg``, ``omega_rod_rad_s``, ``F_A_N``).
    path : str or Path, optional
        Image file to write; None returns the figure.
    title : str, optional
    dpi : int

    Returns
    -------
    Path, or Figure when ``path`` is None

    Raises
    ------
    ModelError
        An unknown or non-numeric column (the message lists the valid columns).
    """
    df = table_of(record)
    numeric = [c for c in df.columns if np.issubdtype(df[c].dtype, np.number)]
    names = check_columns(columns, numeric)
    panels: dict[str, list[str]] = {}
    for c in names:
        panels.setdefault(display_unit(unit_of_column(c))[1], []).append(c)
    xa = x_axis(record)
    fig, axes = _figure(len(panels), height=2.6)
    for ax, (unit, cols) in zip(axes, panels.items(), strict=True):
        f = 1.0
        if unit == "N":
            f, unit = force_unit(*(df[c].to_numpy(float) for c in cols))
        for c in cols:
            values, u = df[c].to_numpy(float), unit_of_column(c)
            if u in ("rad", "deg"):  # continuous, in deg
                y = np.rad2deg(xa.angle(values if u == "rad" else np.deg2rad(values)))
            else:
                y = xa.y(values) * display_unit(u)[0] * f
            ax.plot(xa.x, y, label=c)
        stems = ", ".join(_stem(c) for c in cols)
        ax.set_ylabel(f"{stems if len(stems) <= 30 else 'value'} ({unit})")
        ax.legend(loc="best", fontsize="small")
    xa.setup(axes[-1])
    fig.suptitle(title or " ".join(filter(None, (f"{model_name(record)}:", speed_text(record)))))
    return _save(fig, path, dpi)
