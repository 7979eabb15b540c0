"""What the plots share: the x axis of a record (a full turn as 0..360 deg), titles with the
model's name and speed, one force unit per axis (N or kN), shading of the modes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .table import deg_or_mm, rate_text

__all__ = ["XAxis", "x_axis", "model_name", "speed_text", "force_unit", "shade_modes",
           "display_unit"]


@dataclass(frozen=True)
class XAxis:
    """The x axis of a plot: values in engineering units, and for one full turn of an angle
    the samples taken modulo 360 deg, ordered and closed so the axis runs 0..360 deg.

    Attributes
    ----------
    x : ndarray
        The x values drawn.
    label : str
        The axis label with its unit.
    order : ndarray of int or None
        For a full turn: the sample drawn at each x (samples reordered and the ends repeated).
    """

    x: np.ndarray
    label: str
    order: np.ndarray | None = None

    @property
    def full_turn(self) -> bool:
        return self.order is not None

    def y(self, values) -> np.ndarray:
        """A series of the record's samples, arranged as :attr:`x`."""
        v = np.asarray(values)
        return v if self.order is None else v[self.order]

    def angle(self, values) -> np.ndarray:
        """An angle series (rad) of the record's samples, arranged as :attr:`x`; on a full
        turn (which reorders the samples) made continuous along the axis and shifted by whole
        turns so that its median lies in [-90, 270) deg."""
        if not self.full_turn:
            return np.asarray(values, float)
        theta = np.unwrap(self.y(np.asarray(values, float)))
        ok = np.isfinite(theta)
        if ok.any():
            theta -= 2 * np.pi * np.floor((np.median(theta[ok]) + np.pi / 2) / (2 * np.pi))
        return theta

    def at(self, value_deg: float) -> float:
        """Where a position (deg, or mm for a travel) lies on the axis."""
        return float(value_deg % 360.0) if self.full_turn else float(value_deg)

    def setup(self, ax) -> None:
        """Label ``ax`` (and for a full turn fix it to 0..360 deg, ticks every 60 deg)."""
        ax.set_xlabel(self.label)
        if self.full_turn:
            ax.set_xlim(0.0, 360.0)
            ax.set_xticks(np.arange(0.0, 361.0, 60.0))


def x_axis(record) -> XAxis:
    """The x axis of a record: the swept coordinate (deg or mm) of a sweep or kinetostatic
    analysis that advances monotonically, else the time (s)."""
    values = getattr(record, "values", None)
    over = getattr(record, "over", None)
    if values is not None and over is not None:
        v = np.asarray(values, float)
        d = np.diff(v)
        if v.size < 2 or np.all(d > 0) or np.all(d < 0) or not np.size(getattr(record, "t", [])):
            xs, unit = deg_or_mm(v, record.over_is_angle)
            label = f"{over} ({unit})"
            if unit == "deg" and v.size >= 3 and np.isclose(abs(xs[-1] - xs[0]), 360.0,
                                                            rtol=0, atol=1e-6):
                return _turn(xs, label)
            return XAxis(xs, label)
    return XAxis(np.asarray(record.t, float), "t (s)")


def _turn(xs: np.ndarray, label: str) -> XAxis:
    """One full turn on 0..360 deg: samples modulo 360 in order, the ends repeated one turn
    away so the curves reach both edges."""
    w = np.mod(xs, 360.0)
    order = np.argsort(w, kind="stable")
    x = np.concatenate([[w[order[-1]] - 360.0], w[order], [w[order[0]] + 360.0]])
    return XAxis(x, label, np.concatenate([order[-1:], order, order[:1]]))


def model_name(record) -> str:
    """The name of the record's mechanism (``"mechanism"`` if it has none)."""
    return getattr(getattr(getattr(record, "model", None), "mechanism", None), "name",
                   "mechanism")


def speed_text(record) -> str:
    """The speed of the record's first coordinate (the swept one of a sweep or kinetostatic
    analysis): ``"at 157.08 rad/s (1500 rpm)"``, ``"mean phi' 25.1 rad/s (240 rpm)"`` for a
    simulation; ``""`` when unknown."""
    qdot = getattr(record, "qdot", None)
    if qdot is None or not np.size(qdot):
        return ""
    model = getattr(record, "model", None)
    names = tuple(getattr(record, "coordinate_names", ()) or getattr(model, "coordinate_names",
                                                                      ()))
    over = getattr(record, "over", None)
    k = names.index(over) if over in names else 0
    angles = getattr(model, "coord_is_angle", None)
    angle = bool(angles[k]) if angles is not None else True
    rate = np.asarray(qdot, float)[:, k]
    if over is not None and np.ptp(rate) <= 1e-9 * max(1.0, abs(float(rate[0]))):
        return "at " + rate_text(float(rate[0]), angle)
    name = names[k] if names else "q"
    return f"mean {name}' " + rate_text(float(np.mean(rate)), angle)


def force_unit(*series) -> tuple[float, str]:
    """(factor, unit) of one axis of forces in N: kN once the largest reaches 10 kN."""
    peak = max((float(np.nanmax(np.abs(s))) for s in series
                if np.size(s) and np.isfinite(s).any()), default=0.0)
    return (1e-3, "kN") if peak >= 1e4 else (1.0, "N")


#: a table column's SI unit -> (factor, unit on the plot's axis)
DISPLAY_UNITS = {"rad": (np.rad2deg(1.0), "deg"), "m": (1e3, "mm"), "N*m": (1.0, "N m"),
                 "kg*m^2": (1.0, "kg m^2"), "1": (1.0, "-"), "": (1.0, "-")}


def display_unit(unit: str) -> tuple[float, str]:
    """How a column in ``unit`` (from :func:`~mechdyn.results.table.unit_of_column`) is drawn:
    angles in deg, lengths in mm, the rest in SI."""
    return DISPLAY_UNITS.get(unit, (1.0, unit))


def shade_modes(axes, xaxis: XAxis, mode_index, modes, legend_ax=None) -> None:
    """Tint the span of every mode on ``axes`` (one colour a mode) and name the modes in a
    legend on ``legend_ax`` (default the first axes)."""
    from matplotlib import colormaps
    from matplotlib.patches import Patch

    idx = xaxis.y(np.asarray(mode_index))
    x = xaxis.x
    if x.size < 2 or len(modes) < 2:
        return
    cmap = colormaps["Pastel2"]
    change = np.flatnonzero(np.diff(idx) != 0) + 1
    for a, b in zip(np.r_[0, change], np.r_[change, x.size - 1], strict=True):
        for ax in axes:
            ax.axvspan(x[a], x[b], color=cmap(int(idx[a]) % cmap.N), alpha=0.35, lw=0)
    handles = [Patch(color=cmap(k % cmap.N), alpha=0.5,
                     label="mode: " + (" ".join(sorted(m)) or "-")) for k, m in enumerate(modes)]
    ax = legend_ax if legend_ax is not None else axes[0]
    lines = [ln for ln in ax.lines if not ln.get_label().startswith("_")]
    ax.legend(handles=lines + handles, loc="best", fontsize="small")
