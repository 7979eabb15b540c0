"""The kinetostatic analysis in one mode: the motion prescribed on the driven
coordinates, the multipliers of every row, the driving torques and frame loads
(see :func:`mechdyn.kinetostatics.inverse.kinetostatics`, the public entry, and
the sign conventions there).  Switched trajectories are analysed segment by segment
with this function (:mod:`mechdyn.kinetostatics.switched`).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from ..dynamics.reactions import batched_inverse
from ..errors import ModelError, Status, did_you_mean
from ..friction.law import friction_joints
from ..model.constraints import coordinates, coordinates_gamma, coordinates_jacobian
from ..model.forces import force_model
from ..results.kinetostatics_record import Kinetostatics
from ..results.records import KinetostaticsStats
from ..units import is_quantity, parse_quantity
from .prescribed import _prescribed, independent_subset

__all__ = ["_kinetostatics", "MESSAGES"]

#: the head of the record's message per status
MESSAGES = {
    Status.SUCCESS: "kinetostatic analysis completed",
    Status.REDUNDANT: "completed; reactions of redundant joints are not unique (minimum-norm "
                      "solution reported)",
    Status.SINGULAR_POSITION: "completed with singular positions: the driven coordinates "
                              "lose control there and the reactions are unbounded",
    Status.SELF_LOCKING: "completed with self-locking positions: friction locks the "
                         "mechanism there (no finite driving torque; NaN torques and reactions)",
    Status.PARTIAL: "completed in part: segments whose mode could not be analysed are NaN "
                    "(see warnings)"}


def _on_times(fn: Callable, tt, n_d: int) -> np.ndarray:
    """fn at the times tt (n,), shape (n, n_d): one call on the array when fn accepts
    arrays, else one call per time."""
    tt = np.asarray(tt, dtype=float)
    try:
        out = np.asarray(fn(tt), dtype=float)
        if out.shape[:1] != tt.shape:
            raise ValueError
    except (ValueError, TypeError):
        out = np.array([np.asarray(fn(float(s)), dtype=float) for s in tt.ravel()])
    return out.reshape(tt.size, n_d)


def _derivs(law: Callable, t: np.ndarray, n_d: int):
    """Values and two derivatives of a law of time (5-point central differences)."""
    first = law(float(t[0])) if t.size else None
    if isinstance(first, tuple) and len(first) == 3:
        return tuple(np.array([np.asarray(law(float(s))[i], dtype=float).reshape(n_d)
                               for s in t]) for i in range(3))
    span = float(np.ptp(t)) if t.size > 1 else 1.0
    h = 1e-3 * (span if span > 0 else 1.0)
    y0, yp1, ym1, yp2, ym2 = (_on_times(law, t + d * h, n_d) for d in (0, 1, -1, 2, -2))
    yd = (8 * (yp1 - ym1) - (yp2 - ym2)) / (12 * h)
    ydd = (16 * (yp1 + ym1) - (yp2 + ym2) - 30 * y0) / (12 * h * h)
    return y0, yd, ydd


def _integrate_speed(omega: Callable, t: np.ndarray, start: np.ndarray, n_d: int):
    """q(t) = start + integral of omega, by 5-point Gauss-Legendre per interval."""
    xg, wg = np.polynomial.legendre.leggauss(5)
    q = np.empty((t.size, n_d))
    q[0] = start
    if t.size > 1:
        a, b = t[:-1], t[1:]
        mid, half = 0.5 * (a + b), 0.5 * (b - a)
        nodes = (mid[:, None] + half[:, None] * xg[None, :]).ravel()
        w = _on_times(omega, nodes, n_d).reshape(a.size, xg.size, n_d)
        inc = np.einsum("k,nkd->nd", wg, w) * half[:, None]
        q[1:] = start + np.cumsum(inc, axis=0)
    # (through _on_times: a tuple omega(t) is not a law's (q, qdot, qddot))
    return q, *_derivs(lambda tt: _on_times(omega, tt, n_d), t, n_d)[:2]


def _to_array(v, n_d: int, what: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.ndim == 0:
        a = np.full(n_d, float(a))
    if a.shape != (n_d,):
        raise ValueError(f"{what}: expected {n_d} value(s), got shape {a.shape}")
    return a


def _speeds(model, over_idx: list[int], speed) -> np.ndarray:
    """The constant speeds of the driven coordinates ``over_idx``, SI (rad/s or m/s),
    shape (n_o,): ``speed`` is one value for all or one per coordinate, each a number
    (SI), a unit text (``"60 rpm"``, ``"0.5 m/s"``) or a pint quantity, an angle rate
    for an angle coordinate and a length rate for a length one.

    Raises
    ------
    UnitError
        A unit of the wrong dimension for its coordinate (the message names the
        argument and the coordinate) or a text that is not a quantity.
    ValueError
        Not one value per driven coordinate.
    """
    n_o = len(over_idx)
    if isinstance(speed, (list, tuple)) or (is_quantity(speed) and np.ndim(speed.magnitude)):
        items = list(speed)  # one per coordinate (a pint array quantity: its elements)
    else:
        items = [speed]
    items = [v.item() if isinstance(v, np.generic) else v for v in items]
    if not any(isinstance(v, str) or is_quantity(v) for v in items):
        return _to_array(speed, n_o, "speed")  # SI numbers
    if len(items) not in (1, n_o):
        raise ValueError(f"speed: expected {n_o} value(s), got {len(items)}")
    names, angle = model.coordinate_names, model.coord_is_angle
    return np.array([parse_quantity(
        v, "angular_velocity" if angle[k] else "velocity",
        where=f"speed of {names[k]!r} ({'an angle' if angle[k] else 'a length'} coordinate)")
        for v, k in zip(items * n_o if len(items) == 1 else items, over_idx, strict=True)])


def _kinetostatics(model, *, over=None, speed=None, values=None, t=None, law=None,
                   start=None, trajectory=None, hold=None, mode=None, point=(0.0, 0.0),
                   model_drives="replace", reacting_loads=(), x_guess=None, lay=None,
                   candidates=None) -> Kinetostatics:
    """The analysis in one mode (see :func:`kinetostatics`); a switched trajectory's
    segment gives its rows ``lay`` (a layout with its extra rows), the order in which coordinates
    are chosen as driven (``candidates``) and its first pose as ``x_guess``."""
    t_start = time.perf_counter()
    names = model.coordinate_names
    if mode is None and isinstance(getattr(trajectory, "mode", None), frozenset):
        mode = trajectory.mode
    if lay is None:
        lay = model.layout(mode)
    load_names = {getattr(ld, "name", None) for ld in model.mechanism.loads}
    for nm in reacting_loads:
        if nm not in load_names:
            raise ModelError(did_you_mean(nm, [n for n in load_names if n], "load"))
    warn = [f"load {getattr(ld, 'name', '?')!r} ({type(ld).__name__}) is an extension load "
            f"that kinetostatics does not evaluate; it is left out"
            for ld in model.mechanism.loads if hasattr(ld, "generalized")]
    x_start = model.x_sketch if getattr(model, "x0", None) is None else model.x0
    x_guess = None if x_guess is None else np.asarray(x_guess, dtype=float)
    if x_guess is not None and x_guess.ndim == 1:
        x_start, x_guess = x_guess, None

    # ---------------------------------------------------------- the motion
    over = [over] if isinstance(over, str) else list(over or [])
    over_idx = [model.coordinate_index(c) for c in over]
    didx = independent_subset(model, lay, x_start, over_idx, candidates)
    if trajectory is not None:
        tt = np.asarray(trajectory.t, dtype=float).reshape(-1)
        qd, qd_dot, qd_ddot = (np.asarray(getattr(trajectory, a), dtype=float)
                               .reshape(tt.size, model.n_q)[:, didx]
                               for a in ("q", "qdot", "qddot"))
        tx = getattr(trajectory, "x", None)
        if x_guess is None and np.shape(tx) == (tt.size, model.n_x):
            x_guess = np.asarray(tx, dtype=float)
    else:
        n_o = len(over_idx) if over_idx else 1  # default: the first independent coordinate
        over_idx = didx[:n_o]
        if law is not None and (speed is not None or values is not None):
            raise ValueError("give law= or speed=/values=, not both")
        if law is not None or callable(speed):
            if t is None:
                raise ValueError(("law=" if law is not None else "a speed law omega(t)")
                                 + " needs the times t=")
            tt = np.asarray(t, dtype=float).reshape(-1)
        if law is not None:
            qo, qo_d, qo_dd = _derivs(law, tt, n_o)
        elif callable(speed):
            if start is None:
                start = coordinates(model, x_start)[over_idx]
            qo, qo_d, qo_dd = _integrate_speed(speed, tt, _to_array(start, n_o, "start"), n_o)
        else:
            if speed is None:
                raise ValueError("give the motion: speed= (a constant, 0 for statics, or a "
                                 "callable omega(t) with t=), law= with t=, or trajectory=")
            if t is not None:
                raise ValueError("t= is used with law= or a callable speed, not with a "
                                 "constant speed (time follows from values and speed)")
            w = _speeds(model, over_idx, speed)
            if values is None:
                if not all(model.coord_is_angle[k] for k in over_idx):
                    raise ValueError("values= is needed for a travel coordinate")
                values = np.linspace(0.0, 2 * np.pi, 361)[:, None] * np.where(w < 0, -1.0, 1.0)
            qo = np.asarray(values, dtype=float).reshape(-1, n_o)
            qo_d, qo_dd = np.broadcast_to(w, qo.shape).copy(), np.zeros_like(qo)
            k0 = int(np.argmax(np.abs(w)))
            tt = ((qo[:, k0] - qo[0, k0]) / w[k0]) if w[k0] != 0 else np.zeros(qo.shape[0])
            still = friction_joints(model) if w[k0] == 0 else ()
            if still:
                warn.append("statics (speed 0) of a model with friction in joint(s) "
                            + ", ".join(repr(j) for j in still) + ": at rest the pairs do "
                            "not slide and Coulomb friction is indeterminate, so the torques "
                            "and reactions are those of the frictionless mechanism, the "
                            "losses 0 and the efficiencies NaN; give a speed for the friction "
                            "against the motion (docs/friction.md)")
        extra = didx[n_o:]
        q0 = coordinates(model, x_start)
        for nm, v in (hold or {}).items():
            q0[model.coordinate_index(nm)] = v  # an unknown name raises
        held = q0[extra]
        zero = np.zeros((tt.size, len(extra)))
        qd = np.concatenate([qo, held + zero], axis=1)
        qd_dot, qd_ddot = np.concatenate([qo_d, zero], axis=1), np.concatenate([qo_dd, zero], 1)
        if extra:
            warn.append("coordinate(s) " + ", ".join(
                f"{names[k]!r} = {h:.6g}" for k, h in zip(extra, held, strict=True))
                + " are held fixed (not driven by the given motion); their driving entries "
                  "are holding torques/forces")
    didx = np.asarray(didx, dtype=int)
    n = tt.size
    if n == 0:
        raise ValueError("no positions to analyse")

    # ---------------------------------------------------------- kinematics
    x, xdot, xddot, charted, pos_stats = _prescribed(
        model, lay, didx, qd, qd_dot, qd_ddot, np.asarray(x_start, dtype=float), x_guess)
    G = coordinates_jacobian(model, x)
    q = coordinates(model, x)
    qdot = np.einsum("nqx,nx->nq", G, xdot)
    qddot = np.einsum("nqx,nx->nq", G, xddot) - coordinates_gamma(model, x, xdot)
    # keep the prescribed values exactly (the poses satisfy them to round-off)
    q[:, didx], qdot[:, didx], qddot[:, didx] = qd, qd_dot, qd_ddot

    core = batched_inverse(model, lay, didx, tt, x, xdot, xddot, q, qdot,
                    skip=didx if model_drives == "replace" else (),
                    reacting=tuple(reacting_loads), point=np.asarray(point, dtype=float),
                    charted=charted)
    tau, status = core.pop("tau"), core.pop("status")
    warn.extend(core.pop("warnings"))
    stats = KinetostaticsStats(**core.pop("stats"), positions=n, **pos_stats,
                               seconds=time.perf_counter() - t_start)
    message = MESSAGES[status]
    if status == Status.SINGULAR_POSITION and not stats.singular_positions:
        message = ("completed through bifurcation position(s): the mechanism stays on its "
                   "branch, the driving torques are the limits along it; the reactions are "
                   "unbounded there")
    replaced = [dr.name for dr, k in force_model(model).drives if k in didx]
    if model_drives == "replace" and replaced:
        message += ("; drive(s) " + ", ".join(repr(r) for r in replaced)
                    + " on driven coordinates are replaced by the prescribed motion "
                      "(driving = the whole torque the drive must deliver)")
    over_k = int(didx[0]) if didx.size else 0  # the first driven coordinate is over[0]
    return Kinetostatics(
        over=names[over_k], t=tt, values=q[:, over_k], q=q, qdot=qdot, qddot=qddot, x=x,
        xdot=xdot, xddot=xddot, coordinate_names=tuple(names),
        driven=tuple(names[k] for k in didx),
        driving={names[k]: tau[:, i] for i, k in enumerate(didx)},
        power={names[k]: tau[:, i] * qdot[:, k] for i, k in enumerate(didx)},
        frame_point=np.asarray(point, dtype=float).copy(), mode=lay.mode, status=status,
        message=message, warnings=tuple(warn), stats=stats, model=model,
        **core, element_units={el: "N m" if lay.rowset.is_angle[idx[0]] else "N"
                               for el, idx in lay.elements.items()})
