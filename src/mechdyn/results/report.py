"""Self-contained HTML reports for engineers: the model, its kinematics, its forces.

:func:`write_report` and :func:`report_trajectory` only consume result records
(a :class:`~mechdyn.kinematics.records.KinematicSweep`, a
:class:`~mechdyn.results.kinetostatics_record.Kinetostatics`, a
:class:`~mechdyn.results.trajectory.Trajectory`) and the compiled model; they
run no analysis.  The convenience :func:`mechdyn.cli.report.report` composes
the standard analyses of a model (a sweep over one turn and, for one degree of
freedom or a given speed, the kinetostatic cycle) and hands the records to
:func:`write_report`.

A report is one HTML file: tables (pandas ``to_html``), plots and a drawing of
the mechanism embedded as base64 PNG images, a small inline style sheet; no
other files, no scripts, no network.  Units are in every column heading (the
column names of ``docs/notation.md``).
"""

from __future__ import annotations

import base64
import html
import tempfile
from dataclasses import fields, is_dataclass
from datetime import datetime
from pathlib import Path

import numpy as np

from .._version import __version__
from ..errors import Status
from ..kinematics.sweep import initial_coordinates
from .animate import animate, snapshot
from .events import events_table
from .plot import plot_kinematic_sweep
from .plot_dynamics import plot_trajectory
from .plot_kinetostatics import plot_kinetostatics
from .table import deg_or_mm, output_path, rate_text, written

__all__ = ["write_report", "report_trajectory", "model_tables"]

_CSS = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 2em auto;
       max-width: 62em; color: #222; line-height: 1.4; padding: 0 1em; }
h1 { border-bottom: 2px solid #2c5d8f; padding-bottom: .2em; }
h2 { color: #2c5d8f; margin-top: 1.8em; border-bottom: 1px solid #ccd; }
h3 { margin-bottom: .3em; }
table { border-collapse: collapse; margin: .4em 0 1em 0; font-size: .9em; }
th, td { border: 1px solid #ccd; padding: .25em .6em; text-align: right; }
th { background: #eef2f7; }
td:first-child, th:first-child { text-align: left; }
.note { color: #555; font-size: .9em; }
.status-ok { color: #1a7f37; font-weight: bold; }
.status-bad { color: #b42318; font-weight: bold; }
img { max-width: 100%; border: 1px solid #ddd; margin: .5em 0; }
code { background: #f3f3f3; padding: 0 .25em; }
"""


# ------------------------------------------------------------------ html helpers
def _esc(text) -> str:
    return html.escape(str(text))


def _table(title: str | None, rows, *, digits: int = 6) -> str:
    """A heading (if any) and rows (dicts or a DataFrame) as an HTML table; "" without rows."""
    import pandas as pd

    if not len(rows):
        return ""
    head = f"<h3>{_esc(title)}</h3>\n" if title else ""
    return head + pd.DataFrame(rows).to_html(index=False, border=0, na_rep="",
                                             float_format=lambda v: f"{v:.{digits}g}")


def _join(parts: list[str]) -> str:
    return "\n".join(p for p in parts if p)


def _img(draw, alt: str, kind: str = "png") -> str:
    """An embedded image drawn by ``draw(path)`` into a temporary ``.png`` or ``.gif`` file."""
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / f"image.{kind}"
        draw(p)
        b64 = base64.b64encode(p.read_bytes()).decode("ascii")
    return f'<img alt="{_esc(alt)}" src="data:image/{kind};base64,{b64}">'


def _drawing(record, alt: str, *, animation: bool, trace) -> list[str]:
    """The first frame of a record's motion and, with ``animation``, the GIF of it."""
    out = ["<h3>Drawing</h3>", _img(lambda p: snapshot(record, p, 0, trace=trace), alt)]
    if animation:
        out.append(_img(lambda p: animate(record, p, frames=72, dpi=60, trace=trace),
                        "the motion", "gif"))
    return out


def _write_page(path, title: str, sections: list[str]) -> Path:
    """Write the HTML page of ``sections`` under ``title``."""
    stamp = datetime.now().strftime("%Y-%m-%d %H:%M")
    path = output_path(path)
    with written(path) as tmp:
        tmp.write_text(
            f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{_esc(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
            f"<h1>{_esc(title)}</h1>\n"
            f"<p class=\"note\">mechdyn {__version__}, {stamp}. SI units unless a column says "
            f"otherwise; angles counter-clockwise positive; joint reactions are the force "
            f"on the child body from the parent at the joint point, ground frame.</p>\n"
            + "\n".join(sections) + "\n</body>\n</html>\n", encoding="utf-8")
    return path


def _status(status: str, ok: bool, message: str = "") -> str:
    cls = "status-ok" if ok else "status-bad"
    msg = f" &mdash; {_esc(message)}" if message else ""
    return f'<p>Status: <span class="{cls}">{_esc(status)}</span>{msg}</p>'


# ------------------------------------------------------------------ the model
def _mm(v: float) -> float:
    return float(v) * 1e3


def _pt_text(p) -> str:
    return p if isinstance(p, str) else f"({_mm(p[0]):.6g}, {_mm(p[1]):.6g}) mm"


def _value_text(v) -> str:
    """Short text of a parameter value: numbers to 6 significant digits, sequences shortened."""
    if isinstance(v, (int, float, np.number)) and not isinstance(v, bool):
        return f"{float(v):.6g}"
    if isinstance(v, (tuple, list, np.ndarray)):
        items = list(v)
        if len(items) > 8:
            return f"({len(items)} values: {_value_text(items[0])} .. {_value_text(items[-1])})"
        return "(" + ", ".join(_value_text(a) for a in items) + ")"
    return str(v)


def _element_params(el, skip=("name",)) -> str:
    """Fields of a load or drive dataclass as ``key = value`` text."""
    if not is_dataclass(el):
        return _esc(repr(el))
    parts = []
    for f in fields(el):
        v = getattr(el, f.name)
        if f.name in skip or v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)
                                           and v == 0 and f.name in ("damping", "preload")):
            continue
        if is_dataclass(v):
            v = f"{type(v).__name__}({_element_params(v, skip=())})"
        elif callable(v):
            v = getattr(v, "__name__", "function")
        parts.append(f"{f.name} = {v if isinstance(v, str) else _value_text(v)}")
    return "; ".join(parts)


def model_tables(model) -> dict:
    """Tables describing a compiled model, with units in the column names.

    Parameters
    ----------
    model : Model

    Returns
    -------
    dict of str to pandas.DataFrame
        ``bodies`` (mass, inertia, centre of mass, named points), ``joints``
        (type, parent, child, points, axis), ``coordinates`` (kind, what it
        measures, unit, initial value and rate), ``loads`` and ``drives``
        (kind, name, parameters in SI); empty tables are left out.
    """
    import pandas as pd

    mech = model.mechanism
    rows = {"bodies": [], "ground points": [], "joints": [], "coordinates": [], "loads": [],
            "drives": []}
    for k, b in enumerate(model.body_names):
        body = mech.bodies[b]
        rows["bodies"].append({
            "body": b, "mass_kg": model.mass[k], "J_c_kg_m2": model.inertia[k],
            "com_x_mm": _mm(body.com[0]), "com_y_mm": _mm(body.com[1]),
            "points (body frame)": ", ".join(f"{n} {_pt_text(p)}" for n, p in body.points.items())})
    rows["ground points"] = [{"point": n, "x_mm": _mm(p[0]), "y_mm": _mm(p[1])}
                             for n, p in mech.ground.points.items()]
    for name, j in mech.joints.items():
        kind = model.joint_kind(name)
        lock = kind == "lock"
        note = ("engaged" if j.engaged else "released") if lock else (
            f"({j.axis[0]:.4g}, {j.axis[1]:.4g})" if kind == "prismatic" else "")
        rows["joints"].append({"joint": name, "type": kind, "parent": j.parent, "child": j.child,
                               "parent point": "" if lock else _pt_text(j.parent_point),
                               "child point": "" if lock else _pt_text(j.child_point),
                               "axis / note": note})
    try:
        q0 = initial_coordinates(model)
    except Exception:  # noqa: BLE001 - the report still lists the coordinates
        q0 = np.full(model.n_q, np.nan)
    qd0 = (mech.extras.get("initial") or {}).get("qdot") or {}
    for k, (name, c) in enumerate(mech.coordinates.items()):
        ang = c.is_angle
        rate = float(qd0.get(name, 0.0)) if isinstance(qd0, dict) else 0.0
        rows["coordinates"].append({
            "coordinate": name, "kind": c.kind, "of": c.body if c.kind == "angle" else c.joint,
            "unit": "rad" if ang else "m",
            "initial": f"{np.rad2deg(q0[k]):.6g} deg" if ang else f"{_mm(q0[k]):.6g} mm",
            "initial rate": f"{rate * 30 / np.pi:.6g} rpm" if ang else f"{rate:.6g} m/s"})
    for key, elements in (("loads", mech.loads), ("drives", mech.drives)):
        rows[key] = [{"kind": type(el).__name__, "name": getattr(el, "name", ""),
                      "parameters (SI)": _element_params(el)} for el in elements]
    return {key: pd.DataFrame(r) for key, r in rows.items()
            if r or key in ("bodies", "joints", "coordinates")}


def _model_section(model) -> str:
    mech = model.mechanism
    g = model.gravity
    return _join(["<h2>Model</h2>", mech.description and f"<p>{_esc(mech.description)}</p>",
                  f"<p>{model.n_bodies} moving bodies, {len(model.joint_names)} joints, "
                  f"coordinates {', '.join(model.coordinate_names)} "
                  f"({mech.dof} degree(s) of freedom); gravity ({g[0]:.4g}, {g[1]:.4g}) "
                  "m/s&sup2;.</p>"]
                 + [_table(title.capitalize(), df) for title, df in model_tables(model).items()])


# ------------------------------------------------------------------ kinematics
def _at_text(over_is_angle: bool, v: float) -> str:
    return f"{np.rad2deg(v):.3f} deg" if over_is_angle else f"{_mm(v):.4f} mm"


def _sweep_section(sw, *, animation: bool, trace) -> str:
    ang = sw.over_is_angle
    rate = float(sw.qdot[0, sw.over_index]) if len(sw) else 1.0
    rng = (f"{_at_text(ang, sw.values[0])} to {_at_text(ang, sw.values[-1])}"
           if len(sw) else "no positions")
    parts = ["<h2>Kinematics</h2>",
             f"<p>Sweep of <code>{_esc(sw.over)}</code> over {rng}, {len(sw)} positions, "
             f"at a constant rate of {rate_text(rate, ang)}"
             + (" &mdash; velocities and accelerations are then the first- and "
                "second-order velocity analogs." if rate == 1.0 else ".") + "</p>",
             _status(sw.status, sw.ok, sw.message)]
    if not len(sw):
        return _join(parts)
    summ = sw.summary()
    strokes = []
    for joint, stroke in summ.strokes.items():
        strokes.append({"slider (joint)": joint, "stroke_mm": f"{_mm(stroke):.4f}"})
        for d in summ.dead_centres:
            if d.joint == joint:
                strokes[-1][f"{d.label} at"] = _at_text(ang, d.at)
                strokes[-1][f"{d.label} travel_mm"] = f"{_mm(d.travel):.4f}"
    mu = [(t, np.rad2deg(t.min), np.rad2deg(t.max)) for t in summ.transmission]
    omegas = [(b, *sw.angular(b)[1:]) for b in sw.model.body_names]
    parts += [
        _table("Strokes and dead centres", strokes),
        _table("Transmission angles", [
            {"loop (coupler/rocker)": f"{t.loop.coupler}/{t.loop.rocker}",
             "joint": t.loop.joints[2], "mu_min_deg": f"{lo:.3f}",
             "at (min)": _at_text(ang, t.min_at), "mu_max_deg": f"{hi:.3f}",
             "at (max)": _at_text(ang, t.max_at),
             "largest deviation from 90 deg": f"{max(90 - lo, hi - 90):.3f}"}
            for t, lo, hi in mu]),
        _table("Extreme speeds and accelerations of the named points", [
            {"point": f"{e.body}.{e.point}", "v_max (m/s)": e.v_max,
             "at (v)": _at_text(ang, e.v_max_at), "a_max (m/s²)": e.a_max,
             "at (a)": _at_text(ang, e.a_max_at)} for e in summ.extremes]),
        _table("Angular velocities and accelerations of the bodies", [
            {"body": b, "omega_min_rad_s": om.min(), "omega_max_rad_s": om.max(),
             "alpha_min_rad_s2": al.min(), "alpha_max_rad_s2": al.max()}
            for b, om, al in omegas if np.ptp(om) > 0 or np.any(om)])]
    parts += _drawing(sw, "the mechanism", animation=animation, trace=trace)
    parts += ["<h3>Plot</h3>", _img(lambda p: plot_kinematic_sweep(sw, p), "kinematics plot")]
    return _join(parts)


# ------------------------------------------------------------------ kinetostatics
def _kinetostatics_section(ks, *, harmonics: int = 6) -> str:
    ang = ks.over_is_angle
    parts = ["<h2>Kinetostatics</h2>"]
    if ks.n:
        k = ks.coordinate_names.index(ks.over)
        parts.append(f"<p>Driven coordinate(s) {', '.join(ks.driven)} at constant "
                     f"{_esc(ks.over)}-rate {rate_text(float(ks.qdot[0, k]), ang)}, "
                     f"{ks.n} positions; forces include gravity, inertia and the model's "
                     "loads.</p>")
    parts.append(_status(ks.status, ks.status in (Status.SUCCESS, Status.REDUNDANT), ks.message))
    if not ks.n:
        return _join(parts)
    p = ks.peaks()
    joints = [{"joint": j, "type": ks.joint_kinds[j], "peak force_N": d["peak"],
               "at": _at_text(ang, d["peak_at"]), "RMS force_N": d["rms"]}
              | ({"peak moment_Nm": d["peak_moment"]} if "peak_moment" in d else {})
              for j, d in p["joints"].items()]
    fr, drives = p["frame"], []
    for c, d in p["driving"].items():
        sym, u = ks._drive_unit(c)
        drives.append({"drive": c, f"peak |{sym}|_{u}": abs(d["peak_abs"]),
                       "at": _at_text(ang, d["peak_abs_at"]), f"max_{u}": d["max"],
                       f"min_{u}": d["min"], f"RMS_{u}": d["rms"], f"mean_{u}": d["mean"],
                       "peak power_W": d["peak_power"]})
    parts += [
        _table("Driving torque", drives),
        _table("Peak joint forces", joints),
        _table("Frame (shaking) loads", [
            {"quantity": "|F| frame (N)", "min": np.nan, "max": fr["force_peak"],
             "peak at": _at_text(ang, fr["force_peak_at"])},
            {"quantity": "Fx frame (N)", "min": fr["Fx_min"], "max": fr["Fx_max"], "peak at": ""},
            {"quantity": "Fy frame (N)", "min": fr["Fy_min"], "max": fr["Fy_max"], "peak at": ""},
            {"quantity": f"M frame about ({ks.frame_point[0]:.4g}, {ks.frame_point[1]:.4g}) m "
                         "(N m)", "min": fr["M_min"], "max": fr["M_max"],
             "peak at": _at_text(ang, fr["moment_peak_at"])}])]
    if harmonics > 0 and ang:
        try:
            h = ks.harmonics(harmonics)
        except ValueError as exc:
            parts.append(f'<p class="note">No harmonics: {_esc(exc)}</p>')
        else:  # the shaking force and moment per order of the turn, round-off noise as 0
            cols = ["Fx_frame_N", "Fy_frame_N", "M_frame_Nm"]
            h = h[["order", "f_Hz", *cols]].copy()
            a = h[cols].abs()
            h[cols] = h[cols].mask(a < 1e-9 * np.maximum(a.max(), 1e-300), 0.0)
            parts += ["<h3>Harmonics of the shaking force and moment</h3>",
                      '<p class="note">Amplitudes per order of the crank turn (order 0: the '
                      'mean).</p>', _table(None, h)]
    parts += [f'<p class="note">Warning: {_esc(w)}</p>' for w in ks.warnings]
    parts += ["<h3>Plot</h3>", _img(lambda p: plot_kinetostatics(ks, p), "kinetostatics plot")]
    return _join(parts)


# ------------------------------------------------------------------ public
def write_report(model, path, *, sweep=None, kinetostatics=None, title: str | None = None,
                 animation: bool = False, trace=None) -> Path:
    """Write an HTML report of a model and of its analysis records.

    Parameters
    ----------
    model : Model
        The compiled model (its elements fill the model tables).
    path : str or Path
        The HTML file to write.
    sweep : KinematicSweep, optional
        Adds the kinematics section: strokes and dead centres, transmission angles,
        extreme point speeds and accelerations, a drawing and the plot.
    kinetostatics : Kinetostatics, optional
        Adds the kinetostatics section: peak and RMS driving torque, peak joint
        forces, frame loads and their harmonics, and the plot.
    title : str, optional
        Default ``"<mechanism name>: report"``.
    animation : bool
        Embed an animated GIF of the sweep (adds some 100 kB to 1 MB).
    trace : "BODY.POINT" or (body, point), optional
        Draw this point's path in the drawing and the animation.

    Returns
    -------
    Path
        The file written.
    """
    name = getattr(model.mechanism, "name", "mechanism")
    sections = [_model_section(model)]
    if sweep is not None:
        sections.append(_sweep_section(sweep, animation=animation, trace=trace))
    if kinetostatics is not None:
        sections.append(_kinetostatics_section(kinetostatics))
    return _write_page(path, title or f"{name}: report", sections)


def report_trajectory(traj, path, *, title: str | None = None, animation: bool = False,
                      trace=None, max_events: int = 200) -> Path:
    """Write an HTML report of a simulated motion.

    Parameters
    ----------
    traj : Trajectory
        The record of :func:`mechdyn.simulate` (with its ``model``).
    path : str or Path
        The HTML file to write.
    title : str, optional
        Default ``"<mechanism name>: simulation report"``.
    animation : bool
        Embed an animated GIF of the motion.
    trace : "BODY.POINT" or (body, point), optional
        Draw this point's path.
    max_events : int
        Largest number of events listed.

    Returns
    -------
    Path
        The file written.
    """
    model = traj.model
    name = getattr(getattr(model, "mechanism", None), "name", "mechanism")
    sections = [] if model is None else [_model_section(model)]
    parts = ["<h2>Simulation</h2>", _status(traj.status, traj.success, traj.message)]
    s = traj.stats or {}
    run = {label: s.get(key) for label, key in (
        ("integrator", "integrator"), ("formulation", "formulation"), ("backend", "backend"),
        ("steps", "steps"), ("rejected steps", "rejected"), ("evaluations", "evaluations"),
        ("wall time_s", "wall_time_s"))}
    run["samples"] = traj.n_samples
    if traj.t.size:
        run["t start_s"], run["t end_s"] = float(traj.t[0]), float(traj.t[-1])
    parts.append(_table("Run", [{"quantity": k, "value": str(v)} for k, v in run.items()
                                if v is not None]))
    if traj.t.size:
        rows = []
        for k, c in enumerate(traj.coordinate_names):
            ang = traj.coordinate_is_angle[k] if traj.coordinate_is_angle else True
            (q0, q1), u = deg_or_mm(traj.q[[0, -1], k], ang)
            qd, ur = (traj.qdot[:, k] * 30 / np.pi, "rpm") if ang else (traj.qdot[:, k], "m/s")
            rows.append({"coordinate": c, f"start ({u})": q0, f"end ({u})": q1,
                         f"start rate ({ur})": qd[0], f"end rate ({ur})": qd[-1],
                         f"min rate ({ur})": qd.min(), f"max rate ({ur})": qd.max()})
        parts.append(_table("Coordinates", rows, digits=9))
    if traj.energy and traj.t.size:
        e = traj.energy
        rows = [{"quantity": q, "start": e[key][0], "end": e[key][-1]} for q, key in (
            ("kinetic energy T_J", "kinetic"), ("potential energy U_J", "potential"),
            ("work of non-conservative forces W_nc_J", "work_nc"),
            ("balance T + U - W_nc_J", "balance"))]
        parts.append(_table("Energy balance", rows, digits=9))
        parts.append(f"<p>The balance drifts by at most {traj.energy_drift():.3e} J; the "
                     f"largest constraint residual is {np.max(e['residual']):.3e} "
                     "(m or rad).</p>")
    parts += ["<h3>Events</h3>", "" if traj.events else "<p>No events.</p>",
              _table(None, events_table(traj.events[:max_events], traj.coordinate_names),
                     digits=9)]
    if len(traj.events) > max_events:
        parts.append(f'<p class="note">{len(traj.events) - max_events} more events not listed.</p>')
    if model is not None and traj.t.size:
        parts += _drawing(traj, "the mechanism at the start", animation=animation, trace=trace)
    if traj.t.size:
        parts += ["<h3>Plot</h3>", _img(lambda p: plot_trajectory(traj, p), "trajectory plot")]
    sections.append(_join(parts))
    return _write_page(path, title or f"{name}: simulation report", sections)
