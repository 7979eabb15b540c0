"""The "Loads on the building" section of a report: the load the machine exerts on its
frame over a run or a kinetostatic cycle, switching events marked, its spectrum, and --
when the machine stands on a foundation -- the peak load of every support.

The section only reads what it is given: the frame-load history (t or the crank angle,
Fx, Fy, M about a point) and, optionally, the support loads already distributed by
:func:`mechdyn.foundation.support_loads` (an object with ``names``, ``fx``, ``fy``,
``tension``, ``clamp`` and ``first_opening``: the ``results`` layer does not import the
foundation package, which sits above it).
"""

from __future__ import annotations

import numpy as np

from . import spectrum as _spectrum
from .report_figures import (
    frame_floor_figure,
    frame_load_figure,
    spectrum_figure,
    supports_figure,
)
from .report_html import cleaned, esc, figure_html, join, note, table
from .table import deg_or_mm

__all__ = ["building_section", "has_frame_loads"]

_SERIES = (("Fx", "kN", 1e3), ("Fy", "kN", 1e3), ("|F|", "kN", 1e3), ("M", "kN m", 1e3))


def has_frame_loads(df) -> bool:
    """True when a table has the frame-load columns ``Fx_frame_N`` and ``Fy_frame_N``."""
    return df is not None and "Fx_frame_N" in df and "Fy_frame_N" in df


def _at(x, k, angle: bool | None) -> str:
    if angle is None:
        return f"t = {x[k]:.5g} s"
    return f"{np.rad2deg(x[k]):.1f} deg" if angle else f"{x[k] * 1e3:.4g} mm"


def _mean_rms(x, y) -> tuple[float, float]:
    span = float(x[-1] - x[0]) if x.size > 1 else 0.0
    if span == 0.0 or not np.all(np.diff(x) >= 0):
        return float(np.mean(y)), float(np.sqrt(np.mean(y * y)))
    return (float(np.trapezoid(y, x) / span), float(np.sqrt(np.trapezoid(y * y, x) / span)))


def _extremes(x, series, angle) -> tuple[list[dict], list[dict]]:
    """Rows of peak, min, max, mean, RMS per series and (a run) the dominant components."""
    rows, dom = [], []
    for (name, unit, scale), y in zip(_SERIES, series, strict=True):
        if y is None:
            continue
        k = int(np.argmax(np.abs(y)))
        peak = float(y[k])
        mean, rms = _mean_rms(x, y)
        if angle is None and name != "|F|":
            try:  # peak, mean and RMS as above; the dominant components by least squares
                s = _spectrum.summary(x, y, n=3)
            except ValueError:  # fewer than 8 distinct times
                s = None
            if s is not None:
                mean, rms = s["mean"], s["rms"]
                dom += [{"quantity": f"{name} ({unit})", "f (Hz)": float(r["f_Hz"]),
                         "amplitude": float(r["amplitude"]) / scale}
                        for _, r in s["dominant"].iterrows()]
        big = float(np.max(np.abs(y)))
        rows.append({"quantity": f"{name} ({unit})", "peak": peak / scale,
                     "at": _at(x, k, angle), "min": float(np.min(y)) / scale,
                     "max": float(np.max(y)) / scale,
                     "mean": float(cleaned([mean], big)[0]) / scale,
                     "RMS": rms / scale})
    return rows, dom


def _run_spectrum(t, series, dom, parts: list[str], div: str) -> None:
    """Spectrum of a run (any sampling): dominant components and the amplitude spectra."""
    try:
        lines = []
        for (name, unit, scale), y in zip(_SERIES, series, strict=True):
            if y is None or name == "|F|":
                continue
            sp = _spectrum.spectrum(t, y)
            f, a = sp["f_Hz"].to_numpy(), sp["amplitude"].to_numpy() / scale
            lines.append((f[1:], a[1:], name, unit))
    except ValueError as exc:
        parts.append(note(f"No spectrum: {esc(exc)}"))
        return
    parts += ["<h3>Spectrum</h3>",
              note("Amplitude spectrum of the whole history (resampled uniformly, flat-top "
                   "window: true amplitudes of sinusoids; the mean is left out). The table gives "
                   "the strongest components, refined by least squares on the samples."),
              table("Dominant components", dom) if dom else note(
                  "No dominant periodic component: the history is too short."),
              figure_html(spectrum_figure(lines, title="Spectrum of the frame load"),
                          f"{div}-spectrum")]


def _cycle_spectrum(angle, series, speed: float | None, parts: list[str], div: str,
                    orders: int = 12) -> None:
    """Harmonics of a kinetostatic cycle per order of the turn."""
    rows: dict[int, dict] = {}
    bars = []
    try:
        for (name, unit, scale), y in zip(_SERIES, series, strict=True):
            if y is None or name == "|F|":
                continue
            o = _spectrum.order_spectrum(angle, y, orders=orders)
            amp = cleaned(o["amplitude"].to_numpy() / scale, np.max(np.abs(y)) / scale)
            bars.append((o["order"].to_numpy()[1:], amp[1:], name, unit))
            for k, a in zip(o["order"], amp, strict=True):
                r = rows.setdefault(int(k), {"order": int(k)})
                if speed:
                    r["f (Hz)"] = k * abs(speed) / (2 * np.pi)
                r[f"{name} ({unit})"] = a
    except ValueError as exc:
        parts.append(note(f"No harmonics: {esc(exc)}"))
        return
    parts += ["<h3>Harmonics of the frame force and moment</h3>",
              note("Amplitude per order of the turn (order 0: the mean), the excitation the "
                   "foundation receives at constant speed."),
              table(None, list(rows.values())),
              figure_html(spectrum_figure(bars, xlabel="order of the turn", bars=True,
                                          title="Harmonics of the frame load"),
                          f"{div}-harmonics")]


def _supports_part(x, xlabel, supports, angle, transitions, div: str) -> list[str]:
    rows = []
    for n in supports.names:
        fx, fy = np.asarray(supports.fx[n], float), np.asarray(supports.fy[n], float)
        res = np.hypot(fx, fy)
        k = int(np.argmax(res))
        bolt = n in supports.tension
        row = {"support": n, "kind": "anchor bolt" if bolt else "isolator",
               "peak |F| (kN)": res[k] / 1e3, "at": _at(x, k, angle),
               ("peak shear" if bolt else "peak |Fx|") + " (kN)": np.max(np.abs(fx)) / 1e3,
               ("peak axial share" if bolt else "peak |Fy|") + " (kN)":
                   np.max(np.abs(fy)) / 1e3}
        if bolt:
            ten, cl = np.asarray(supports.tension[n]), np.asarray(supports.clamp[n])
            c = int(np.argmin(cl))
            row |= {"peak tension (kN)": np.max(ten) / 1e3, "least clamp force (kN)": cl[c] / 1e3,
                    "least clamp at": _at(x, c, angle)}
        rows.append(row)
    opening = supports.first_opening
    text = ("No anchor-bolt joint opens: every bolt keeps its preload."
            if opening is None else f"The joint of bolt <b>{esc(opening[0])}</b> opens first "
            f"(clamp force zero: the preload is lost) at t = {opening[1]:.6g} s.")
    if not supports.tension:
        text = ""
    return ["<h3>Supports</h3>",
            note("The frame and its base taken as rigid: the frame load shared among the "
                 "supports by their stiffness; forces the supports pass on to the floor."),
            table("Peak load of every support", rows), text and f"<p>{text}</p>",
            figure_html(supports_figure(x, xlabel, supports, transitions=transitions,
                                        title="Loads of the supports"), f"{div}-supports")]


def _mounted_part(t, Fx, Fy, M, mounted, modes, rpm, transitions, div: str) -> list[str]:
    """The base on its elastic mounts: the force passed to the floor against the rigid base,
    the base's motion, and its natural frequencies beside the excitation orders."""
    parts = ["<h3>On the elastic mounts</h3>",
             note("The frame and its base as one rigid body with its mass and inertia on the "
                  "supports (springs and dampers), driven by the frame load (one way: the "
                  "base's motion does not act back on the machine).")]
    if modes is not None:
        rows = []
        for k, (f, label) in enumerate(zip(modes.frequencies, modes.labels, strict=True)):
            row = {"mode": k + 1, "f (Hz)": float(f), "motion": str(label)}
            if rpm:
                order = f / (rpm / 60.0)
                near = [o for o in (1, 2, 3, 4) if abs(f / (o * rpm / 60.0) - 1) <= 0.2]
                row["order of the running speed"] = float(order)
                row["near order (±20 %)"] = ", ".join(map(str, near)) or "-"
            rows.append(row)
        parts.append(table("Natural frequencies of the mounted base", rows)
                     + (note(f"Running speed {rpm:.4g} rpm (the mean speed of the run): orders "
                             f"1 to 4 at " + ", ".join(f"{o * rpm / 60:.4g}" for o in range(1, 5))
                             + " Hz.") if rpm else ""))
    if mounted is not None:
        floor = np.asarray(mounted.floor, float)
        mt = np.asarray(mounted.t, float)
        rigid = np.hypot(Fx, Fy)
        elastic = np.hypot(floor[:, 0], floor[:, 1])
        kr, ke = int(np.argmax(rigid)), int(np.argmax(elastic))
        u = np.asarray(mounted.u, float)
        rows = [{"base": "rigid", "peak |F| (kN)": rigid[kr] / 1e3, "at": _at(t, kr, None),
                 "peak |M| (kN m)": np.max(np.abs(M)) / 1e3 if M is not None else None},
                {"base": "on the mounts", "peak |F| (kN)": elastic[ke] / 1e3,
                 "at": _at(mt, ke, None),
                 "peak |M| (kN m)": np.max(np.abs(floor[:, 2])) / 1e3,
                 "peak base motion x (mm)": np.max(np.abs(u[:, 0])) * 1e3,
                 "y (mm)": np.max(np.abs(u[:, 1])) * 1e3,
                 "θ (mrad)": np.max(np.abs(u[:, 2])) * 1e3}]
        ratio = elastic[ke] / rigid[kr] if rigid[kr] > 0 else float("nan")
        f = frame_floor_figure(t, rigid, mt, elastic, transitions=transitions)
        parts += [table("Force passed to the floor", rows),
                  note(f"On the mounts the peak force to the floor is {ratio:.3g} times the "
                       "rigid base's" + (" (the mounts amplify it)." if ratio > 1 else ".")),
                  figure_html(f, f"{div}-floor")]
    return parts


def building_section(*, x, Fx, Fy, M=None, point=(0.0, 0.0), angle: bool | None = None,
                     xlabel: str = "t (s)", transitions=(), spans=None, speed=None,
                     supports=None, mounted=None, modes=None, rpm: float | None = None,
                     div: str = "building", intro: str = "") -> str:
    """The HTML of "Loads on the building".

    Parameters
    ----------
    x : array_like, shape (n,)
        Time of a run, s (``angle`` None), or the driven coordinate of a kinetostatic cycle
        (rad, ``angle`` True; m, ``angle`` False).
    Fx, Fy, M : array_like, shape (n,)
        Force (N) and moment about ``point`` (N m) the machine exerts on its frame.
    point : (float, float)
        The point of M, m.
    xlabel : str
        Label of the x axis of the plots (its values as plotted: ``x`` is converted to deg
        or mm for a cycle).
    transitions : list of Transition
        Switching events of a run (merged), marked in the history.
    spans : list of (t0, t1, label), optional
        Modes of a run, shaded.
    speed : float, optional
        Constant rate of a cycle, rad/s (the frequency of each order).
    supports : SupportLoads, optional
        The loads of the supports of a foundation over the same samples.
    mounted : MountedResponse, optional
        The response of the base on elastic mounts to the same history (a run): the force
        passed to the floor (``floor``, (n, 3)) and the base's motion (``u``).
    modes : Modes, optional
        Natural frequencies (``frequencies``, Hz) and ``labels`` of the mounted base.
    rpm : float, optional
        Running speed, rpm, for the excitation orders beside the natural frequencies.
    """
    x = np.asarray(x, float)
    Fx, Fy = np.asarray(Fx, float), np.asarray(Fy, float)
    M = None if M is None else np.asarray(M, float)
    good = np.isfinite(x) & np.isfinite(Fx) & np.isfinite(Fy)
    if M is not None:
        good &= np.isfinite(M)
    parts = ["<h2>Loads on the building</h2>",
             "<p>The load the machine exerts on its frame, and through it on the foundation "
             "and the floor: force (Fx, Fy) and moment M about "
             f"({point[0] * 1e3:.4g}, {point[1] * 1e3:.4g}) mm, counter-clockwise positive"
             + (", over the run" if angle is None else ", over the kinetostatic cycle")
             + (f"; {intro}" if intro else "") + ".</p>"]
    if good.sum() < 2:
        return join(parts + [note("No finite frame-load samples.")])
    x, Fx, Fy = x[good], Fx[good], Fy[good]
    M = None if M is None else M[good]
    series = [Fx, Fy, np.hypot(Fx, Fy), M]
    xplot = x if angle is None else deg_or_mm(x, angle)[0]
    rows, dom = _extremes(x, series, angle)
    parts += [table("Frame load extremes", rows),
              figure_html(frame_load_figure(xplot, xlabel, Fx, Fy, M, point=point,
                                            transitions=transitions, spans=spans,
                                            title="Frame load history"), f"{div}-history")]
    if angle is None:
        _run_spectrum(x, series, dom, parts, div)
    elif angle:
        _cycle_spectrum(x, series, speed, parts, div)
    if supports is not None:
        sx = np.asarray(supports.t, float) if angle is None else xplot
        if sx.size == np.asarray(supports.applied).shape[0]:
            parts += _supports_part(sx, xlabel, supports, angle, transitions, div)
        else:
            parts.append(note("The support loads do not match the frame-load samples: "
                              "not shown."))
    if (mounted is not None or modes is not None) and angle is None:
        parts += _mounted_part(x, Fx, Fy, M, mounted, modes, rpm, transitions, div)
    return join(parts)

