"""Self-contained HTML reports for engineers: the model, its kinematics, its forces, and
the loads it sends into the building.

:func:`write_report` and :func:`report_trajectory` only consume result records
(a :class:`~mechdyn.kinematics.records.KinematicSweep`, a
:class:`~mechdyn.results.kinetostatics_record.Kinetostatics`, a
:class:`~mechdyn.results.trajectory.Trajectory`, the support loads of a foundation) and
the compiled model; they run no analysis.  The convenience
:func:`mechdyn.cli.report.report` composes the standard analyses of a model (a sweep over
one turn and the kinetostatic cycle, other coordinates held) and hands the records to
:func:`write_report`.

A report is one HTML file that works offline: tables with rounded values and the unit in
every heading, one interactive plotly figure per section (plotly.js embedded once), the
animation of the motion beside it (a GIF, or the first frame), a small inline style sheet;
no other files, no network.  Lengths are in mm and angles in degrees.
"""

from __future__ import annotations

from dataclasses import fields, is_dataclass
from pathlib import Path

import numpy as np

from ..errors import Status
from ..kinematics.sweep import initial_coordinates
from ..mechanism.coordinate import BODY_KINDS
from ..mechanism.joint import has_friction
from .animate import animate, snapshot
from .report_building import building_section, has_frame_loads
from .report_events import events_rows, merged_events, mode_spans
from .report_figures import kinetostatics_figure, sweep_figure, trajectory_figure
from .report_html import esc, figure_html, fmt, img, join, note, side_by_side, status_html, table
from .report_html import write_page as _write_page
from .table import deg_or_mm, rate_text

__all__ = ["write_report", "report_trajectory", "model_tables"]


def _motion(record, alt: str, *, animation: bool, trace) -> str:
    """The animation of a record's motion (a GIF) or, without ``animation``, its first frame."""
    if animation:
        return "<h3>Motion</h3>\n" + img(
            lambda p: animate(record, p, frames=72, dpi=80, trace=trace), alt, "gif")
    return "<h3>Drawing</h3>\n" + img(lambda p: snapshot(record, p, 0, trace=trace), alt)


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
        return esc(repr(el))
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


def _friction_cells(joint) -> dict:
    """The friction columns of a joint's row: mu and the pin radius or guide length (mm),
    with a viscous term named; {} for a joint without friction."""
    if not has_friction(joint):
        return {}
    size = getattr(joint, "pin_radius", getattr(joint, "guide_length", 0.0))
    cells = {"friction mu": joint.friction, "pin radius / guide length (mm)": _mm(size)}
    if joint.viscous > 0:
        cells["friction mu"] = f"{joint.friction:.4g} (viscous {joint.viscous:.4g} SI)"
    return cells


def model_tables(model) -> dict:
    """Tables describing a compiled model, with units in the column names.

    Parameters
    ----------
    model : Model

    Returns
    -------
    dict of str to pandas.DataFrame
        ``bodies`` (mass, inertia, centre of mass, named points), ``joints``
        (type, parent, child, points, axis; with friction in a pair also mu and the pin
        radius or guide length), ``coordinates`` (kind, what it
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
                               "axis / note": note, **_friction_cells(j)})
    if any("friction mu" in r for r in rows["joints"]):  # friction columns on every row
        for r in rows["joints"]:
            r.setdefault("friction mu", "")
            r.setdefault("pin radius / guide length (mm)", "")
    try:
        q0 = initial_coordinates(model)
    except Exception:  # noqa: BLE001 - the report still lists the coordinates
        q0 = np.full(model.n_q, np.nan)
    qd0 = (mech.extras.get("initial") or {}).get("qdot") or {}
    for k, (name, c) in enumerate(mech.coordinates.items()):
        ang = c.is_angle
        rate = float(qd0.get(name, 0.0)) if isinstance(qd0, dict) else 0.0
        rows["coordinates"].append({
            "coordinate": name, "kind": c.kind, "of": c.body if c.kind in BODY_KINDS else c.joint,
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
    return join(["<h2>Model</h2>", mech.description and f"<p>{esc(mech.description)}</p>",
                 f"<p>{model.n_bodies} moving bodies, {len(model.joint_names)} joints, "
                 f"coordinates {', '.join(model.coordinate_names)} "
                 f"({mech.dof} degree(s) of freedom); gravity ({g[0]:.4g}, {g[1]:.4g}) "
                 "m/s&sup2;.</p>"]
                + [table(title.capitalize(), df, sig=5)
                   for title, df in model_tables(model).items()])


# ------------------------------------------------------------------ kinematics
def _at_text(over_is_angle: bool, v: float) -> str:
    return f"{np.rad2deg(v):.2f} deg" if over_is_angle else f"{v * 1e3:.3f} mm"


def _sweep_section(sw, *, animation: bool, trace) -> str:
    ang = sw.over_is_angle
    rate = float(sw.qdot[0, sw.over_index]) if len(sw) else 1.0
    rng = (f"{_at_text(ang, sw.values[0])} to {_at_text(ang, sw.values[-1])}"
           if len(sw) else "no positions")
    k = sw.over_index
    others = [f"{c} = {_at_text(sw.model.coord_is_angle[i], sw.q[0, i])}"
              for i, c in enumerate(sw.model.coordinate_names)
              if i != k and len(sw) and np.ptp(sw.q[:, i]) == 0.0]
    parts = ["<h2>Kinematics</h2>",
             f"<p>Sweep of <code>{esc(sw.over)}</code> over {rng}, {len(sw)} positions, "
             f"at a constant rate of {rate_text(rate, ang)}"
             + (f"; {', '.join(others)} held" if others else "")
             + (" &mdash; velocities and accelerations are then the first- and "
                "second-order velocity analogs." if rate == 1.0 else ".") + "</p>",
             status_html(sw.status, sw.ok, sw.message)]
    if not len(sw):
        return join(parts)
    summ = sw.summary()
    strokes = []
    for joint, stroke in summ.strokes.items():
        strokes.append({"slider (joint)": joint, "stroke (mm)": stroke * 1e3})
        for d in summ.dead_centres:
            if d.joint == joint:
                strokes[-1][f"{d.label} at"] = _at_text(ang, d.at)
                strokes[-1][f"{d.label} travel (mm)"] = d.travel * 1e3
    mu = [(t, np.rad2deg(t.min), np.rad2deg(t.max)) for t in summ.transmission]
    omegas = [(b, *sw.angular(b)[1:]) for b in sw.model.body_names]
    parts += [
        table("Strokes and dead centres", strokes, sig=6),
        table("Transmission angles", [
            {"loop (coupler/rocker)": f"{t.loop.coupler}/{t.loop.rocker}",
             "joint": t.loop.joints[2], "μ min (deg)": lo, "at (min)": _at_text(ang, t.min_at),
             "μ max (deg)": hi, "at (max)": _at_text(ang, t.max_at),
             "largest deviation from 90 deg (deg)": max(90 - lo, hi - 90)}
            for t, lo, hi in mu]),
        table("Extreme speeds and accelerations of the named points", [
            {"point": f"{e.body}.{e.point}", "v max (m/s)": e.v_max,
             "at (v)": _at_text(ang, e.v_max_at), "a max (m/s²)": e.a_max,
             "at (a)": _at_text(ang, e.a_max_at)} for e in summ.extremes]),
        table("Angular velocities and accelerations of the bodies", [
            {"body": b, "ω min (rad/s)": om.min(), "ω max (rad/s)": om.max(),
             "|ω| max (rpm)": np.abs(om).max() * 30 / np.pi,
             "α min (rad/s²)": al.min(), "α max (rad/s²)": al.max()}
            for b, om, al in omegas if np.ptp(om) > 0 or np.any(om)])]
    name = getattr(sw.model.mechanism, "name", "mechanism")
    fig = sweep_figure(sw, trace=trace, title=f"{name}: kinematics at constant "
                                              f"{sw.over}-rate {rate_text(rate, ang)}")
    parts += ["<h3>Plot</h3>", side_by_side(
        figure_html(fig, "kinematics"),
        _motion(sw, "the mechanism", animation=animation, trace=trace))]
    return join(parts)


# ------------------------------------------------------------------ kinetostatics
def _kinetostatics_section(ks) -> str:
    ang = ks.over_is_angle
    parts = ["<h2>Kinetostatics</h2>"]
    if ks.n:
        k = ks.coordinate_names.index(ks.over)
        held = [c for c in ks.driven if c != ks.over]
        model = ks.model
        held_text = ""
        if held:
            try:
                q0 = initial_coordinates(model) if model is not None else None
            except Exception:  # noqa: BLE001 - the values held are stated all the same
                q0 = None
            vals = []
            for c in held:
                i = ks.coordinate_names.index(c)
                is_ang = bool(model.coord_is_angle[i]) if model is not None else True
                origin = ("its initial value" if q0 is not None
                          and abs(ks.q[0, i] - q0[i]) <= 1e-9 else "as assembled")
                vals.append(f"<code>{esc(c)}</code> at {_at_text(is_ang, ks.q[0, i])} "
                            f"({origin})")
            held_text = (f" The other coordinate(s) are held: {', '.join(vals)}, each by the "
                         "holding torque or force shown.")
        parts.append(f"<p>Driven coordinate <code>{esc(ks.over)}</code> at the constant "
                     f"rate {rate_text(float(ks.qdot[0, k]), ang)}, {ks.n} positions; forces "
                     f"include gravity, inertia and the model's loads"
                     + (" and the friction in the pairs" if ks.power_out is not None else "")
                     + f".{held_text}</p>")
    parts.append(status_html(ks.status, ks.status in (Status.SUCCESS, Status.REDUNDANT),
                             ks.message))
    if not ks.n:
        return join(parts)
    p = ks.peaks()
    joints = []
    for j, d in p["joints"].items():
        row = {"joint": j, "type": ks.joint_kinds[j], "peak |F| (kN)": d["peak"] / 1e3,
               "at": _at_text(ang, d["peak_at"]), "RMS |F| (kN)": d["rms"] / 1e3}
        if "peak_moment" in d:
            row["peak moment (N m)"] = d["peak_moment"]
        joints.append(row)
    drives = []
    for c, d in p["driving"].items():
        sym, u = ks._drive_unit(c)
        unit = "N m" if u == "Nm" else "N"
        drives.append({"coordinate": c, "role": "driven" if c == ks.over else "held",
                       f"peak |{sym}| ({unit})": abs(d["peak_abs"]),
                       "at": _at_text(ang, d["peak_abs_at"]), f"max ({unit})": d["max"],
                       f"min ({unit})": d["min"], f"mean ({unit})": d["mean"],
                       f"RMS ({unit})": d["rms"], "peak power (kW)": d["peak_power"] / 1e3})
    elements = [{"element": el, "peak": d["peak"] / (1e3 if d["unit"] == "N" else 1.0),
                 "unit": "kN" if d["unit"] == "N" else d["unit"],
                 "at": _at_text(ang, d["peak_at"])} for el, d in p["elements"].items()]
    units = {ks._drive_unit(c)[1] for c in p["driving"]}
    what = ("Driving torque" if units == {"Nm"} else "Driving force" if units == {"N"}
            else "Driving torques and forces")
    parts += [table(what, drives), table("Peak joint forces", joints),
              table("Stops, contacts and locks", elements)]
    if ks.power_out is not None:
        parts += _friction_part(ks)
    parts += [note(f"Warning: {esc(w)}") for w in ks.warnings]
    name = getattr(getattr(ks.model, "mechanism", None), "name", "mechanism")
    parts += ["<h3>Plot</h3>",
              figure_html(kinetostatics_figure(
                  ks, title=f"{name}: {what.lower()}, joint forces" + (
                      ", friction losses and efficiency" if ks.power_out is not None
                      else "")), "kinetostatics")]
    return join(parts)


def _friction_part(ks) -> list[str]:
    """Friction in the pairs: the cycle efficiency with the energies in, out and lost, and
    per pair the energy lost, its share and the peak power lost."""
    e = ks.energies()
    ang = ks.over_is_angle
    line = (f"<p><b>Friction in the pairs:</b> cycle efficiency {fmt(ks.cycle_efficiency)} "
            f"({fmt(100 * ks.cycle_efficiency, 3)} %); energy in {fmt(e['input'])} J, out "
            f"{fmt(e['output'])} J, lost {fmt(e['losses'])} J over the cycle")
    eta = ks.efficiency
    if np.isfinite(eta).any():
        k = int(np.nanargmax(ks.driving_total_power))
        line += (f"; instantaneous efficiency {fmt(eta[k])} at the peak driving power "
                 f"({_at_text(ang, ks.values[k])})")
    line += ".</p>"
    if ks.locked is not None and ks.locked.any():
        line += note(f"{int(ks.locked.sum())} self-locked position(s): see the warnings.")
    rows = []
    for j, p in ks.losses.items():
        k = int(np.nanargmax(p)) if np.isfinite(p).any() else 0
        lost = e[f"loss_{j}"]
        rows.append({"pair": j, "type": ks.joint_kinds.get(j, ""), "energy lost (J)": lost,
                     "share of the losses (%)": 100 * lost / e["losses"] if e["losses"]
                     else float("nan"),
                     "peak power lost (W)": p[k], "at": _at_text(ang, ks.values[k])})
    return [line, table("Friction losses per pair", rows)]


def _kinetostatics_building(ks, supports) -> str:
    """"Loads on the building" of a kinetostatic cycle."""
    if not ks.n:
        return ""
    k = ks.coordinate_names.index(ks.over)
    return building_section(
        x=ks.values, Fx=ks.frame_force[:, 0], Fy=ks.frame_force[:, 1], M=ks.frame_moment,
        point=tuple(ks.frame_point), angle=ks.over_is_angle,
        xlabel=f"{ks.over} ({'deg' if ks.over_is_angle else 'mm'})",
        speed=float(ks.qdot[0, k]), supports=supports, div="building-cycle")


# ------------------------------------------------------------------ public
def write_report(model, path, *, sweep=None, kinetostatics=None, title: str | None = None,
                 animation: bool = True, trace=None, supports=None) -> Path:
    """Write an HTML report of a model and of its analysis records.

    Parameters
    ----------
    model : Model
        The compiled model (its elements fill the model tables).
    path : str or Path
        The HTML file to write.
    sweep : KinematicSweep, optional
        Adds the kinematics section: strokes and dead centres, transmission angles,
        extreme point speeds and accelerations, the interactive plot and the animation.
    kinetostatics : Kinetostatics, optional
        Adds the kinetostatics section (driving and holding torques, peak joint forces,
        the plot) and "Loads on the building" (frame force and moment, their harmonics).
    title : str, optional
        Default ``"<mechanism name>: report"``.
    animation : bool
        Embed an animated GIF of the sweep beside its plot (some 100 kB to 1 MB); else its
        first frame.
    trace : "BODY.POINT" or (body, point), optional
        Draw this point's path in the drawing and the animation, and plot it.
    supports : SupportLoads, optional
        The loads of a foundation's supports over the kinetostatic cycle
        (:func:`mechdyn.foundation.support_loads`): per-support peaks in "Loads on the
        building".

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
        sections.append(_kinetostatics_building(kinetostatics, supports))
    return _write_page(path, title or f"{name}: report", sections)


def _run_table(traj) -> str:
    s = traj.stats
    run = {"integrator": s.integrator or None, "formulation": s.formulation or None,
           "backend": s.backend or None, "steps": s.steps, "rejected steps": s.rejected,
           "evaluations": s.evaluations}
    if s.wall_time_s is not None:
        run["wall time (s)"] = f"{float(s.wall_time_s):.3g}"
    run["samples"] = traj.n_samples
    if traj.t.size:
        run["t start (s)"], run["t end (s)"] = f"{traj.t[0]:.6g}", f"{traj.t[-1]:.6g}"
    return table("Run", [{"quantity": k, "value": str(v)} for k, v in run.items()
                         if v is not None])


def _coordinates_table(traj) -> str:
    rows = []
    for k, c in enumerate(traj.coordinate_names):
        ang = traj.coordinate_is_angle[k] if traj.coordinate_is_angle else True
        q = traj.q[:, k]
        (q0, q1), u = deg_or_mm(q[[0, -1]], ang)
        qd, ur = (traj.qdot[:, k] * 30 / np.pi, "rpm") if ang else (traj.qdot[:, k], "m/s")
        rows.append({"coordinate": c, "unit": u, "start": q0, "end": q1, "rate unit": ur,
                     "start rate": qd[0], "end rate": qd[-1], "min rate": np.nanmin(qd),
                     "max rate": np.nanmax(qd)})
    for r in rows:  # round-off noise of a held or locked coordinate as 0
        for key in ("start", "end", "start rate", "end rate", "min rate", "max rate"):
            r[key] = 0.0 if abs(r[key]) < 1e-9 else r[key]
    return table("Coordinates", rows, sig=6)


def _mean_rpm(traj) -> float | None:
    """The mean speed of the run's first angle coordinate, rpm (None without one)."""
    for k, angle in enumerate(traj.coordinate_is_angle or ()):
        if angle and traj.t.size > 1 and traj.t[-1] > traj.t[0]:
            return abs(float(traj.q[-1, k] - traj.q[0, k]) / float(traj.t[-1] - traj.t[0])) \
                * 30 / np.pi
    return None


def report_trajectory(traj, path, *, title: str | None = None, animation: bool = True,
                      trace=None, max_events: int = 200, supports=None, mounted=None,
                      modes=None, point=(0.0, 0.0)) -> Path:
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
        Embed an animated GIF of the motion beside its plot; else its first frame.
    trace : "BODY.POINT" or (body, point), optional
        Draw this point's path.
    max_events : int
        Largest number of events listed (after merging the records of one transition).
    supports : SupportLoads, optional
        The loads of a foundation's supports over the run
        (:func:`mechdyn.foundation.support_loads`): per-support peaks in "Loads on the
        building".
    mounted : MountedResponse, optional
        The response of the base on elastic mounts to the run's frame loads
        (:func:`mechdyn.foundation.mounted_response`): the force passed to the floor
        against the rigid base's, and the base's motion.
    modes : Modes, optional
        The natural frequencies of the mounted base
        (:func:`mechdyn.foundation.natural_frequencies`), beside the excitation orders of
        the run's mean speed.
    point : (float, float)
        The point the run's frame moment ``M_frame_Nm`` is about, m (the ``point`` of
        :func:`mechdyn.simulate`).

    Returns
    -------
    Path
        The file written.
    """
    model = traj.model
    name = getattr(getattr(model, "mechanism", None), "name", "mechanism")
    sections = [] if model is None else [_model_section(model)]
    parts = ["<h2>Simulation</h2>", status_html(traj.status, traj.success, traj.message),
             _run_table(traj)]
    if traj.t.size:
        parts.append(_coordinates_table(traj))
    if traj.energy and traj.t.size:
        e = traj.energy
        rows = [{"quantity": q, "start (J)": e[key][0], "end (J)": e[key][-1]} for q, key in (
            ("kinetic energy T", "kinetic"), ("potential energy U", "potential"),
            ("work of non-conservative forces W_nc", "work_nc"),
            ("balance T + U - W_nc", "balance"))]
        parts.append(table("Energy balance", rows, sig=6))
        parts.append(f"<p>The balance drifts by at most {traj.energy_drift():.3e} J; the "
                     f"largest constraint residual is {np.max(e['residual']):.3e} "
                     "(m or rad).</p>")
    transitions = merged_events(traj.events)
    shown = transitions[:max_events]
    parts += ["<h3>Events</h3>",
              "" if transitions else "<p>No events.</p>",
              note(f"{len(transitions)} event(s); the {len(traj.events)} records of the run "
                   "merged where several elements take part in one transition (same time, "
                   "same modes before and after).") if len(transitions) < len(traj.events)
              else "",
              table(None, events_rows(shown, traj.coordinate_names, traj.coordinate_is_angle))]
    if len(transitions) > max_events:
        parts.append(note(f"{len(transitions) - max_events} more events not listed."))
    vs = traj.switching
    spans = (mode_spans(traj.t, vs["mode_index"], vs["modes"])
             if vs is not None and getattr(model, "has_switching", True) else None)
    if traj.t.size:
        fig = trajectory_figure(traj, transitions=transitions, spans=spans,
                                title=f"{name}: simulated motion")
        motion = (_motion(traj, "the motion", animation=animation, trace=trace)
                  if model is not None else "")
        parts += ["<h3>Plot</h3>", side_by_side(figure_html(fig, "simulation"), motion)]
    sections.append(join(parts))
    df = traj.to_dataframe(energy=False, bodies=False, degrees=False) \
        if traj.t.size > 1 and vs is not None else None
    if has_frame_loads(df):
        sections.append(building_section(
            x=df["t_s"].to_numpy(float), Fx=df["Fx_frame_N"].to_numpy(float),
            Fy=df["Fy_frame_N"].to_numpy(float),
            M=df["M_frame_Nm"].to_numpy(float) if "M_frame_Nm" in df else None,
            point=point, transitions=transitions, spans=spans, supports=supports,
            mounted=mounted, modes=modes, rpm=_mean_rpm(traj), div="building-run"))
    return _write_page(path, title or f"{name}: simulation report", sections)
