"""The reduction method for one-degree-of-freedom machines (lecture notes, METHOD.md §2).

A machine with one degree of freedom is replaced by one *link of reduction*
turning with the generalized coordinate ``phi`` (or with a chosen link) that
carries

* the **reduced moment of inertia** ``J_red(phi) = 2 T / omega^2
  = sum_k (m_k |v_ck / omega|^2 + J_ck (omega_k / omega)^2)``, kg m^2, from the
  exact velocity analogs of the centres of mass, ``v_c / omega = B_r + B_theta
  R(A c_k)`` (R: rotation by +90 deg, A c_k: the centre of mass offset turned
  into the ground frame);
* its derivative ``dJ_red/dphi = 2 sum_k (m_k v_c' . a_c' + J_ck w' alpha')``,
  kg m^2/rad, exact: ``a_c'`` and ``alpha'`` are the acceleration bias of the
  kinematics at unit speed (``d B / dphi = b(x, B)``, ``qdot = 1``);
* the **reduced torque** ``M_red(phi, omega, t) = Q_phi = B^T F + M_drive``,
  N m, by equal power of every applied force, moment and drive;
* the **reduced mass** at a point P, ``m_red = 2 T / v_P^2 = J_red / |v_P/omega|^2``, kg.

Its equation of motion (lecture notes eq. 7.12) is

    J(phi) domega/dt + 1/2 omega^2 dJ/dphi = M_red(phi, omega, t),

with ``J = J_red + J_extra`` (rotor and gears reduced to the coordinate,
flywheel).  Since ``d(J omega^2 / 2) / dphi = M_red``, the *energy form*
``J omega^2 / 2 = J_0 omega_0^2 / 2 + integral M_red dphi`` holds when M_red
depends on the position only.

Public names
------------
reduce_model
    The reduced quantities of a model tabulated over a cycle -> :class:`Reduction`.
ReducedMachine, Member, MemberLoad
    The reduced 1-DOF machine: from a model, from a table, from a transmission
    of velocity ratios (belt drives, gear trains), or from plain functions.
run_reduced, energy_speed
    Time integration of the reduced equation (with :mod:`mechdyn.integrate`) and
    the energy form.
steady_state, size_flywheel, startup
    The periodic steady motion (shooting on omega at phi0) and its coefficient of
    speed fluctuation; flywheel sizing by the energy method, confirmed by
    simulation; start-up from rest and load transients.
mode_mechanism
    A variable-structure mechanism in one mode (locks engaged, frozen
    coordinates dropped), e.g. the press in its 1-DOF working mode.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import IntegrationError, LockupError, ModelError, did_you_mean
from ..model import Model

__all__ = ["Reduction", "reduce_model", "ReducedMachine", "Member", "MemberLoad",
           "ReducedRun", "run_reduced", "energy_speed", "SteadyCycle", "steady_state",
           "FlywheelSizing", "size_flywheel", "StartupResult", "startup",
           "reduced_kinematics", "mode_mechanism"]

TWO_PI = 2.0 * math.pi


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float, copy=True)
    a.setflags(write=False)
    return a


# ============================================================================ kinematics
def _rot(th, s):
    """A(theta) s for th (..., nb) and s (nb, 2) -> (..., nb, 2)."""
    c, sn = np.cos(th), np.sin(th)
    return np.stack([c * s[:, 0] - sn * s[:, 1], sn * s[:, 0] + c * s[:, 1]], axis=-1)


def _perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _lin_solve(J, rhs):
    """Solve [Phi_x; g_x] y = rhs (least squares for redundant constraint sets)."""
    if J.shape[-1] == J.shape[-2]:
        return np.linalg.solve(J, rhs)
    return np.linalg.pinv(J) @ rhs


def reduced_kinematics(model: Model, x, layout=None) -> dict:
    """Exact first and second transmission functions of a 1-DOF model (batched).

    Parameters
    ----------
    model : Model
        A model with ``n_q == 1``.
    x : array_like, shape (..., n_x)
        Solved body poses.
    layout : ConstraintLayout, optional

    Returns
    -------
    dict of ndarray
        ``B`` (..., n_x): dx/dphi of the body frames; ``b`` (..., n_x): d2x/dphi2
        (the acceleration bias at unit speed); ``vc``, ``ac`` (..., n_bodies, 2):
        centre-of-mass analogs dr_c/dphi (m/rad) and their derivatives
        (m/rad^2); ``w``, ``al`` (..., n_bodies): angular analogs dtheta/dphi and
        d2theta/dphi2; ``J`` (...): J_red, kg m^2; ``dJ`` (...): dJ_red/dphi,
        kg m^2/rad; ``Jf`` (..., n_x, n_x): the Jacobian [Phi_x; g_x].
    """
    from ..kinematics.constraints import coordinates_gamma, coordinates_jacobian, gamma, jacobian

    lay = layout or model.layout()
    x = np.asarray(x, dtype=float)
    Jf = np.concatenate([jacobian(model, x, lay), coordinates_jacobian(model, x)], axis=-2)
    rhs = np.zeros(Jf.shape[:-1] + (1,))
    rhs[..., lay.n_rows:, 0] = 1.0
    B = _lin_solve(Jf, rhs)[..., 0]
    g = np.concatenate([gamma(model, x, B, lay), coordinates_gamma(model, x, B)], axis=-1)
    b = _lin_solve(Jf, g[..., None])[..., 0]
    th = x[..., 2::3]
    arm = _rot(th, model.com)
    w, al = B[..., 2::3], b[..., 2::3]
    vr = np.stack([B[..., 0::3], B[..., 1::3]], axis=-1)
    ar = np.stack([b[..., 0::3], b[..., 1::3]], axis=-1)
    vc = vr + w[..., None] * _perp(arm)
    ac = ar + al[..., None] * _perp(arm) - (w**2)[..., None] * arm
    m, jc = model.mass, model.inertia
    J = np.sum(m * np.sum(vc * vc, axis=-1) + jc * w * w, axis=-1)
    dJ = 2.0 * np.sum(m * np.sum(vc * ac, axis=-1) + jc * w * al, axis=-1)
    return {"B": B, "b": b, "vc": vc, "ac": ac, "w": w, "al": al, "J": J, "dJ": dJ, "Jf": Jf}


class _ModelEvaluator:
    """Exact reduced quantities of a 1-DOF model at any position, with branch continuation."""

    def __init__(self, model: Model, coordinate: str | None = None, *, mode=None, x0=None):
        if model.n_q != 1:
            raise ModelError(
                f"the reduction method needs one degree of freedom, but the model has "
                f"{model.n_q} coordinates ({', '.join(model.coordinate_names)}); reduce a "
                f"1-DOF model (for a variable-structure machine: the model of one mode)")
        if coordinate is not None and coordinate not in model.coordinate_names:
            raise ModelError(did_you_mean(coordinate, model.coordinate_names, "coordinate"))
        from ..dynamics.forces import force_model
        from ..kinematics.assembly import assemble
        from ..kinematics.constraints import coordinates

        self.model = model
        self.coordinate = model.coordinate_names[0]
        self.is_angle = bool(model.coord_is_angle[0])
        self.layout = model.layout(mode)
        self.forces = force_model(model)
        if x0 is None:
            x0 = getattr(model, "x0", None)
            if x0 is None:
                x0 = assemble(model, layout=self.layout)
        self.x_last = np.array(x0, dtype=float)
        self.q_last = float(coordinates(model, self.x_last)[0])
        self.max_step = math.radians(5.0) if self.is_angle else 0.05 * model.length_scale
        self._cache_q = None
        self._cache = None
        self._pred = None  # (q, x, B, b) of the last full evaluation

    def pose(self, phi: float) -> np.ndarray:
        """Solved pose at ``phi``, continued from the last pose (keeps the branch).

        Near the last evaluated position the Newton solve starts from the
        second-order predictor ``x + B dphi + b dphi^2 / 2``.
        """
        from ..kinematics.assembly import solve_position

        phi = float(phi)
        pred = self._pred
        if pred is not None and abs(phi - pred[0]) <= 3.0 * self.max_step:
            d = phi - pred[0]
            guess = pred[1] + pred[2] * d + 0.5 * pred[3] * d * d
            x = self._chord(phi, guess, pred[4])
            if x is None:
                x = solve_position(self.model, np.array([phi]), guess, layout=self.layout,
                                   check_singular=False)
        else:
            n = max(1, int(math.ceil(abs(phi - self.q_last) / self.max_step)))
            x = self.x_last
            for q in np.linspace(self.q_last, phi, n + 1)[1:]:
                x = solve_position(self.model, np.array([q]), x, layout=self.layout,
                                   check_singular=False)
        self.x_last, self.q_last = x, phi
        return x

    def _chord(self, phi, x, Jf, max_iter: int = 8):
        """Chord Newton from a close predictor with the last Jacobian; None if it stalls."""
        from ..kinematics.constraints import coordinates, residual

        tol = 1e-13 * max(self.model.length_scale, 1e-3)
        if Jf.shape[0] != Jf.shape[1]:
            return None
        prev = np.inf
        for _ in range(max_iter):
            F = np.concatenate([residual(self.model, x, self.layout),
                                coordinates(self.model, x) - phi])
            err = float(np.max(np.abs(F)))
            if err <= tol:
                return x
            if err > 0.5 * prev:
                return x if err <= 1e3 * tol else None
            prev = err
            x = x - np.linalg.solve(Jf, F)
        return None

    def poses(self, phis) -> np.ndarray:
        """Poses along a sequence of positions (continuation in the given order), (n, n_x).

        Positions are solved one by one only at a coarse stride (at most
        ``max_step`` apart); every other position starts from a second-order
        Taylor predictor of its coarse neighbour, ``x_c + B dphi + b dphi^2/2``,
        and all are polished by one batched Newton solve.
        """
        from ..kinematics.assembly import solve_position

        phis = np.asarray(phis, float).reshape(-1)
        n = phis.size
        if n <= 4:
            return np.array([self.pose(p) for p in phis])
        coarse = [0]
        for i in range(1, n):
            if abs(phis[i] - phis[coarse[-1]]) > self.max_step:
                coarse.append(i - 1 if i - 1 != coarse[-1] else i)
        xc = np.array([self.pose(phis[i]) for i in coarse])
        kin = reduced_kinematics(self.model, xc, self.layout)
        owner = np.searchsorted(np.asarray(coarse), np.arange(n), side="right") - 1
        d = (phis - phis[np.asarray(coarse)][owner])[:, None]
        guess = xc[owner] + kin["B"][owner] * d + 0.5 * kin["b"][owner] * d * d
        xs = solve_position(self.model, phis[:, None], guess, layout=self.layout,
                            check_singular=False)
        self.x_last, self.q_last = xs[-1], float(phis[-1])
        self._cache_q = None
        return xs

    def state(self, phi: float):
        """(x, kinematics dict) at one position (cached for the last position)."""
        if self._cache_q != phi:
            x = self.pose(phi)
            kin = reduced_kinematics(self.model, x, self.layout)
            self._cache = (x, kin)
            self._cache_q = phi
            self._pred = (phi, x, kin["B"], kin["b"], kin["Jf"])
        return self._cache

    def inertia(self, phi):
        _, kin = self.state(float(phi))
        return float(kin["J"]), float(kin["dJ"])

    def generalized_forces(self, t, phi, omega, x, B) -> tuple[float, float]:
        """(M_forces, M_drive): B^T F of the applied forces and the drive torque, N m."""
        F, Qd = self.forces.applied(float(t), x, B * omega, np.array([phi]), np.array([omega]))
        return float(B @ F), float(Qd[0])

    def torque(self, t, phi, omega):
        x, kin = self.state(float(phi))
        mf, md = self.generalized_forces(t, phi, omega, x, kin["B"])
        return mf + md


def mode_mechanism(mechanism, *, engage: Sequence[str] = (), offsets: dict | None = None,
                   drop: Sequence[str] = ()):
    """A copy of a mechanism with locks engaged and the coordinates they freeze removed.

    The reduction method needs one degree of freedom; a variable-structure
    machine has it in some modes only (the clutchless press in its working mode:
    rocker locked onto the slider).  This builds that mode as a mechanism of its
    own.

    Parameters
    ----------
    mechanism : Mechanism
    engage : sequence of str
        Locks to engage.
    offsets : dict, optional
        Lock name -> pose (x m, y m, theta rad) of the child frame in the parent
        frame held by the lock; default the lock's own offset (or the sketch).
    drop : sequence of str
        Coordinates to remove (those the engaged locks freeze).

    Returns
    -------
    Mechanism
        The original is not changed; initial values of dropped coordinates are
        removed from ``extras["initial"]``.
    """
    import dataclasses

    from ..mechanism.joint import Lock

    offsets = dict(offsets or {})
    joints = dict(mechanism.joints)
    probs = []
    for name in engage:
        j = joints.get(name)
        if not isinstance(j, Lock):
            locks = [n for n, jj in joints.items() if isinstance(jj, Lock)]
            probs.append(did_you_mean(name, locks, "lock"))
            continue
        off = offsets.pop(name, j.offset)
        joints[name] = dataclasses.replace(j, engaged=True,
                                           offset=None if off is None else tuple(map(float, off)))
    for name in offsets:
        probs.append(f"offsets: lock {name!r} is not in engage")
    coords = {k: v for k, v in mechanism.coordinates.items() if k not in set(drop)}
    for name in drop:
        if name not in mechanism.coordinates:
            probs.append(did_you_mean(name, mechanism.coordinates, "coordinate"))
    if probs:
        raise ModelError(probs)
    extras = dict(mechanism.extras)
    init = extras.get("initial")
    if isinstance(init, dict):
        extras["initial"] = {k: {c: v for c, v in dict(d or {}).items() if c in coords}
                             for k, d in init.items()}
    return dataclasses.replace(mechanism, joints=joints, coordinates=coords,
                               loads=list(mechanism.loads), drives=list(mechanism.drives),
                               extras=extras)


# ============================================================================ the table
@dataclass(frozen=True)
class Reduction:
    """Reduced quantities of a 1-DOF mechanism over a range of positions.

    All arrays have shape (n,) over the positions.  With a link of reduction the
    quantities refer to that link: ``J_red = 2T / omega_link^2``,
    ``dJ_red_dphi`` is taken with respect to the link's angle, ``M_red`` is the
    torque on the link by equal power.

    Attributes
    ----------
    coordinate : str
        The generalized coordinate.
    link : str or None
        The link of reduction (None: the coordinate itself).
    is_angle : bool
        Whether the coordinate is an angle (else a travel: kg and N instead of
        kg m^2 and N m).
    phi : ndarray
        Values of the coordinate, rad (m for a travel).
    link_angle : ndarray or None
        Absolute angle of the link of reduction, rad.
    ratio : ndarray
        Transmission function d(link angle)/dphi (ones without a link).
    J_red, dJ_red_dphi : ndarray
        Reduced moment of inertia of the mechanism (kg m^2) and its derivative
        (kg m^2/rad).
    J_extra : ndarray
        Inertia added by the drives and the flywheel, reduced to the link
        (``J_extra_coordinate / ratio^2``), kg m^2.
    M_red, M_drive, M_forces : ndarray
        Reduced torque of all forces and drives, of the drives alone and of the
        applied forces (gravity, springs, loads) alone, N m.
    omega : ndarray
        Speed of the link of reduction at which M_red was evaluated, rad/s.
    t : float
        Time at which M_red was evaluated, s.
    point : (str, str) or None
        (body, point) of the reduced mass.
    m_red, v_ratio : ndarray or None
        Reduced mass at the point, ``2 T / v_P^2`` (kg, whole machine including
        J_extra), and ``|v_P| / omega`` (m/rad).
    status, message, events, stats
        As every result record.
    """

    coordinate: str
    link: str | None
    is_angle: bool
    phi: np.ndarray
    link_angle: np.ndarray | None
    ratio: np.ndarray
    J_red: np.ndarray
    dJ_red_dphi: np.ndarray
    J_extra: np.ndarray
    M_red: np.ndarray
    M_drive: np.ndarray
    M_forces: np.ndarray
    omega: np.ndarray
    t: float = 0.0
    point: tuple | None = None
    m_red: np.ndarray | None = None
    v_ratio: np.ndarray | None = None
    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: dict = field(default_factory=dict)

    @property
    def J_total(self) -> np.ndarray:
        """J_red + J_extra, kg m^2."""
        return self.J_red + self.J_extra

    @property
    def position(self) -> np.ndarray:
        """The position variable of the link of reduction: the link angle, or phi."""
        return self.phi if self.link_angle is None else self.link_angle

    def work(self) -> np.ndarray:
        """Work of M_red from the first position, integral M_red d(position), J (trapezoid)."""
        from scipy.integrate import cumulative_trapezoid

        return cumulative_trapezoid(self.M_red, self.position, initial=0.0)

    def to_dataframe(self):
        """The table with unit-suffixed columns (``phi_deg``, ``J_red_kgm2``, ``M_red_Nm`` ...)."""
        import pandas as pd

        ang = self.is_angle or self.link is not None
        iu, tu, du = ("kgm2", "Nm", "kgm2") if ang else ("kg", "N", "kg")
        cols: dict = {}
        if self.is_angle:
            cols["phi_deg"] = np.degrees(self.phi)
            cols["phi_rad"] = self.phi
        else:
            cols["s_m"] = self.phi
        if self.link is not None:
            cols[f"theta_{self.link}_deg"] = np.degrees(self.link_angle)
            cols["ratio"] = self.ratio
        cols[f"J_red_{iu}"] = self.J_red
        cols[f"dJ_red_dphi_{du}" + ("" if ang else "_per_m")] = self.dJ_red_dphi
        cols[f"J_extra_{iu}"] = self.J_extra
        cols[f"J_total_{iu}"] = self.J_total
        cols[f"M_red_{tu}"] = self.M_red
        cols[f"M_drive_{tu}"] = self.M_drive
        cols[f"M_forces_{tu}"] = self.M_forces
        cols["omega_rad_s" if ang else "v_m_s"] = self.omega
        if self.m_red is not None:
            cols["m_red_kg"] = self.m_red
            cols["v_ratio_m_rad"] = self.v_ratio
        return pd.DataFrame(cols)

    def machine(self, model: Model | None = None, **kwargs) -> ReducedMachine:
        """A fast :class:`ReducedMachine` interpolating this table (see
        :meth:`ReducedMachine.from_reduction`)."""
        return ReducedMachine.from_reduction(self, model, **kwargs)


def reduce_model(model: Model, *, coordinate: str | None = None, link: str | None = None,
                 point: tuple[str, object] | None = None, steps: int = 361,
                 phi=None, start: float = 0.0, period: float | None = None,
                 omega: float = 1.0, t: float = 0.0, extra_inertia: float | None = None,
                 mode=None, x0=None) -> Reduction:
    """Tabulate the reduced quantities of a 1-DOF model over a cycle.

    Parameters
    ----------
    model : Model
        A compiled model with one generalized coordinate (in ``mode``).
    coordinate : str, optional
        Its name (checked; default the model's only coordinate).
    link : str, optional
        A body taken as the link of reduction: quantities are divided by its
        angular-velocity analog (``J_link = J_red / (dtheta_link/dphi)^2``,
        ``M_link = M_red / (dtheta_link/dphi)``).  Where that analog vanishes
        (a rocker at its dead positions) they are infinite.
    point : (body, point), optional
        Also give the reduced mass at this point, ``2 T / v_P^2``, kg.
    steps : int
        Number of positions (default 361: every degree of a turn, ends included).
    phi : array_like, shape (n,), optional
        Explicit positions (rad or m), followed in order; overrides
        ``steps``/``start``/``period``.
    start, period : float
        The cycle ``start ... start + period`` (rad; default period 2 pi; required
        for a travel coordinate unless ``phi`` is given).
    omega : float
        Speed of the link of reduction at which forces and drives are evaluated
        (rad/s, or m/s); matters for velocity-dependent loads and motors only.
    t : float
        Time at which loads are evaluated, s.
    extra_inertia : float, optional
        Inertia added on the coordinate, kg m^2; default the drives' rotor and
        gear inertia (``extra_inertia()`` of their torque objects).
    mode : iterable of str, optional
        Engaged locks (default the model's initial mode).
    x0 : array_like, shape (n_x,), optional
        A pose on the wanted assembly branch (default the sketch).

    Returns
    -------
    Reduction
    """
    from ..mechanism.motors import extra_inertia_by_coordinate

    ev = _ModelEvaluator(model, coordinate, mode=mode, x0=x0)
    if phi is None:
        if steps is None or int(steps) < 2:
            raise ModelError(f"steps must be an integer >= 2, got {steps!r}")
        if period is None:
            if not ev.is_angle:
                raise ModelError(f"coordinate {ev.coordinate!r} is a travel: give the "
                                 f"positions (phi=...) or the period (m) of the cycle")
            period = TWO_PI
        phis = float(start) + np.linspace(0.0, float(period), int(steps))
    else:
        phis = np.asarray(phi, dtype=float).reshape(-1)
        if phis.size < 1 or not np.all(np.isfinite(phis)):
            raise ModelError("phi must be a non-empty sequence of finite positions")
    if extra_inertia is None:
        j_extra = extra_inertia_by_coordinate(model.mechanism).get(ev.coordinate, 0.0)
    else:
        j_extra = float(extra_inertia)
        if not math.isfinite(j_extra) or j_extra < 0:
            raise ModelError(f"extra_inertia must be >= 0 kg*m^2, got {extra_inertia!r}")

    xs = ev.poses(phis)
    kin = reduced_kinematics(model, xs, ev.layout)
    n = phis.size
    if link is None:
        ratio = np.ones(n)
        dratio = np.zeros(n)
        link_angle = None
    else:
        k = model.body_index(link)
        if k >= model.n_bodies:
            raise ModelError(f"link of reduction: the ground cannot be the link; choose one of "
                             f"{', '.join(model.body_names)}")
        ratio = kin["w"][:, k]
        dratio = kin["al"][:, k]
        link_angle = xs[:, 3 * k + 2]
    J, dJ = kin["J"], kin["dJ"]
    with np.errstate(divide="ignore", invalid="ignore"):
        qdot = float(omega) / ratio
        mf = np.empty(n)
        md = np.empty(n)
        for i in range(n):
            qd = qdot[i] if np.isfinite(qdot[i]) else 0.0
            mf[i], md[i] = ev.generalized_forces(t, phis[i], qd, xs[i], kin["B"][i])
        J_link = J / ratio**2
        dJ_link = (dJ / ratio**2 - 2.0 * J * dratio / ratio**3) / ratio
        J_extra = j_extra / ratio**2
        M_f, M_d = mf / ratio, md / ratio
    m_red = v_ratio = None
    if point is not None:
        body, pt = point
        kb = model.body_index(body)
        s = model.point_local(body, pt)
        arm = _rot(xs[:, 3 * kb + 2][:, None], s[None, :])[:, 0, :]
        v = np.stack([kin["B"][:, 3 * kb], kin["B"][:, 3 * kb + 1]], axis=-1) \
            + kin["B"][:, 3 * kb + 2][:, None] * _perp(arm)
        v_ratio = np.hypot(v[:, 0], v[:, 1])
        with np.errstate(divide="ignore"):
            m_red = (J + j_extra) / v_ratio**2
        point = (body, pt)
    bad = ~np.isfinite(J_link) | (np.abs(ratio) <= 1e-9 * np.max(np.abs(ratio), initial=0.0))
    message = ""
    status = "success"
    if np.any(bad):
        status = "singular"
        message = (f"the angular-velocity analog of link {link!r} vanishes at "
                   f"{int(bad.sum())} position(s) (e.g. phi = "
                   f"{np.degrees(phis[np.argmax(bad)]):.4g} deg): the reduced quantities are "
                   f"infinite there; choose a link that turns continuously")
    return Reduction(
        coordinate=ev.coordinate, link=link, is_angle=ev.is_angle, phi=_frozen(phis),
        link_angle=None if link_angle is None else _frozen(link_angle),
        ratio=_frozen(ratio), J_red=_frozen(J_link), dJ_red_dphi=_frozen(dJ_link),
        J_extra=_frozen(J_extra), M_red=_frozen(M_f + M_d), M_drive=_frozen(M_d),
        M_forces=_frozen(M_f), omega=_frozen(np.full(n, float(omega))), t=float(t),
        point=point, m_red=None if m_red is None else _frozen(m_red),
        v_ratio=None if v_ratio is None else _frozen(v_ratio), status=status,
        message=message, stats={"positions": n, "extra_inertia_coordinate": j_extra})


# ============================================================================ the machine
@dataclass(frozen=True)
class Member:
    """A moving member of a transmission, given by its velocity ratio to the input.

    Parameters
    ----------
    name : str
    inertia : float
        Moment of inertia about its axis (kg m^2) for ``kind="rotation"``, mass
        (kg) for ``kind="translation"``.
    ratio : float or callable
        ``omega_i / omega`` (rotation) or ``v_i / omega`` (translation, m/rad):
        a constant, or a function of the input position phi.
    ratio_derivative : float or callable, optional
        d(ratio)/dphi; default 0 for a constant ratio, a central difference for
        a callable.
    kind : {"rotation", "translation"}
    """

    name: str
    inertia: float
    ratio: float | Callable = 1.0
    ratio_derivative: float | Callable | None = None
    kind: str = "rotation"

    def __post_init__(self):
        if self.kind not in ("rotation", "translation"):
            raise ModelError(f"member {self.name!r}: kind must be 'rotation' or "
                             f"'translation', got {self.kind!r}")
        if not math.isfinite(float(self.inertia)) or float(self.inertia) < 0:
            unit = "kg*m^2" if self.kind == "rotation" else "kg"
            raise ModelError(f"member {self.name!r}: inertia must be >= 0 {unit}, "
                             f"got {self.inertia!r}")


@dataclass(frozen=True)
class MemberLoad:
    """A torque (or force) on a member, reduced by equal power.

    Parameters
    ----------
    name : str
    value : float or callable
        N m (or N) in the member's positive direction of motion; a constant or
        ``value(t, phi, omega) -> float`` of the input's position and speed.
    ratio : float or callable
        The member's velocity ratio to the input (as in :class:`Member`).
    """

    name: str
    value: float | Callable = 0.0
    ratio: float | Callable = 1.0


def _ratio(r, phi):
    return float(r(phi)) if callable(r) else float(r)


def _dratio(m: Member, phi, h=1e-6):
    if m.ratio_derivative is not None:
        return _ratio(m.ratio_derivative, phi)
    if not callable(m.ratio):
        return 0.0
    return (_ratio(m.ratio, phi + h) - _ratio(m.ratio, phi - h)) / (2 * h)


class ReducedMachine:
    """A one-degree-of-freedom machine reduced to one link.

    Equation of motion: ``J(phi) phi'' + 1/2 J'(phi) phi'^2 = M(t, phi, phi')``
    with ``J = J_red(phi) + extra_inertia``.

    Parameters
    ----------
    inertia : callable
        ``inertia(phi) -> (J_red, dJ_red/dphi)``, kg m^2 and kg m^2/rad.
    torque : callable
        ``torque(t, phi, omega) -> M_red``, N m (forces and drives).
    extra_inertia : float
        Constant inertia added on the link (rotor through the gear, flywheel), kg m^2.
    drive : object, optional
        The drive on the link (an object with ``torque_at``; a
        :class:`~mechdyn.mechanism.motors.GearStage` also gives the motor-side
        torque in :func:`startup`).  Informational: its torque must already be
        part of ``torque``.
    period : float
        Angle of one cycle, rad (2 pi for a crank).
    name : str
    coordinate : str
        Name of the coordinate of the link of reduction (for reports).
    nominal_speed : float, optional
        A speed near the working point, rad/s (start of the steady-state search);
        default from the drive (rated speed through the gear).

    Build one with :meth:`from_model`, :meth:`from_reduction`,
    :meth:`from_transmission` or :meth:`constant`.
    """

    def __init__(self, inertia: Callable, torque: Callable, *, extra_inertia: float = 0.0,
                 drive=None, period: float = TWO_PI, name: str = "machine",
                 coordinate: str = "phi", nominal_speed: float | None = None):
        ej = float(extra_inertia)
        if not math.isfinite(ej) or ej < 0:
            raise ModelError(f"extra_inertia must be >= 0 kg*m^2, got {extra_inertia!r}")
        if not (math.isfinite(float(period)) and period > 0):
            raise ModelError(f"period must be > 0 rad, got {period!r}")
        self._inertia = inertia
        self._torque = torque
        self.extra_inertia = ej
        self.drive = drive
        self.period = float(period)
        self.name = name
        self.coordinate = coordinate
        self.nominal_speed = nominal_speed if nominal_speed is not None else _nominal(drive)

    # ------------------------------------------------------------------ evaluation
    def inertia(self, phi: float) -> tuple[float, float]:
        """(J, dJ/dphi) of the whole machine (extra inertia included), kg m^2 and kg m^2/rad."""
        j, dj = self._inertia(float(phi))
        return float(j) + self.extra_inertia, float(dj)

    def torque(self, t: float, phi: float, omega: float) -> float:
        """Reduced torque of forces and drives, N m."""
        return float(self._torque(float(t), float(phi), float(omega)))

    def acceleration(self, t: float, phi: float, omega: float) -> float:
        """phi'' = (M - 1/2 J' omega^2) / J, rad/s^2."""
        j, dj = self.inertia(phi)
        if not j > 0:
            raise IntegrationError(f"reduced inertia J = {j:.6g} kg*m^2 is not positive",
                                   t=t, q=[phi])
        return (self.torque(t, phi, omega) - 0.5 * dj * omega * omega) / j

    def rhs(self, t, q, qdot):
        """The right-hand side q'' = f(t, q, q') for :mod:`mechdyn.integrate`."""
        return np.array([self.acceleration(t, q[0], qdot[0])])

    def drive_torque(self, omega: float) -> float:
        """Torque of the drive on the link (N m), 0 without a drive."""
        if self.drive is None:
            return 0.0
        return float(self.drive.torque_at(omega))

    def motor_torque(self, omega: float) -> float | None:
        """Motor-side torque (N m) when the drive is a gear stage, else the drive torque."""
        if self.drive is None:
            return None
        fn = getattr(self.drive, "motor_torque", None)
        return float(fn(omega)) if fn is not None else self.drive_torque(omega)

    def speed_dependent(self, t: float = 0.0) -> bool:
        """Whether the reduced torque changes with the speed (a motor, a damper)."""
        for p in np.linspace(0.0, self.period, 7)[:-1]:
            a = self.torque(t, p, 10.0)
            b = self.torque(t, p, 20.0)
            if abs(a - b) > 1e-9 * max(1.0, abs(a)):
                return True
        return False

    def with_extra_inertia(self, added: float) -> ReducedMachine:
        """A copy with ``added`` kg m^2 more on the link (a flywheel)."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.extra_inertia = self.extra_inertia + float(added)
        return new

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_model(cls, model: Model, *, coordinate: str | None = None,
                   extra_inertia: float | None = None, mode=None, x0=None,
                   period: float | None = None) -> ReducedMachine:
        """The exact reduced machine of a 1-DOF model.

        Every evaluation solves the position (continued from the last one, so
        the assembly branch is kept), the exact analogs and the generalized
        force of all loads and drives; ``extra_inertia`` defaults to the
        drives' rotor and gear inertia.
        """
        from ..mechanism.motors import extra_inertia_by_coordinate

        ev = _ModelEvaluator(model, coordinate, mode=mode, x0=x0)
        if extra_inertia is None:
            extra_inertia = extra_inertia_by_coordinate(model.mechanism).get(ev.coordinate, 0.0)
        drive = _single_drive(model, ev.coordinate)
        if period is None:
            period = TWO_PI if ev.is_angle else 1.0
        m = cls(ev.inertia, ev.torque, extra_inertia=extra_inertia, drive=drive, period=period,
                name=model.mechanism.name, coordinate=ev.coordinate)
        m.evaluator = ev
        return m

    @classmethod
    def from_reduction(cls, red: Reduction, model: Model | None = None, *,
                       extra_inertia: float | None = None, drive=None) -> ReducedMachine:
        """A fast machine interpolating a one-cycle :class:`Reduction` table.

        J_red is a periodic cubic spline (its derivative the spline's), the
        applied-force torque M_forces is interpolated linearly (punch loads are
        discontinuous) and periodically; the drive torque is evaluated live from
        ``drive`` (default: the model's drive on the coordinate), so the table's
        M_drive is not used.  Valid when the loads depend on the position only.
        """
        from scipy.interpolate import CubicSpline

        if red.link is not None:
            raise ModelError("from_reduction: reduce to the coordinate (link=None) to build a "
                             "machine")
        phi = np.asarray(red.phi)
        period = phi[-1] - phi[0]
        if not period > 0 or not np.all(np.diff(phi) > 0):
            raise ModelError("from_reduction: the table must cover one cycle with increasing "
                             "positions (first and last position one period apart)")
        jj = np.array(red.J_red, dtype=float)
        jj[-1] = jj[0]
        spline = CubicSpline(phi, jj, bc_type="periodic")
        coef = spline.c.T.tolist()  # per interval: c3, c2, c1, c0 in powers of (u - phi_i)
        xs = phi.tolist()
        mf = np.array(red.M_forces, dtype=float).tolist()
        n_int = len(xs) - 1
        phi0 = xs[0]
        h = period / n_int
        uniform = bool(np.allclose(np.diff(phi), h, rtol=1e-12, atol=0.0))
        if drive is None and model is not None:
            drive = _speed_drive(model, red.coordinate)

        def locate(p):
            u = phi0 + (p - phi0) % period
            if uniform:
                i = int((u - phi0) / h)
            else:
                i = bisect.bisect_right(xs, u) - 1
            return u, min(max(i, 0), n_int - 1)

        def inertia(p):
            u, i = locate(p)
            d = u - xs[i]
            c3, c2, c1, c0 = coef[i]
            return ((c3 * d + c2) * d + c1) * d + c0, (3.0 * c3 * d + 2.0 * c2) * d + c1

        def torque(t, p, w):
            u, i = locate(p)
            r = (u - xs[i]) / (xs[i + 1] - xs[i])
            m = mf[i] + r * (mf[i + 1] - mf[i])
            return m + (float(drive.torque_at(w)) if drive is not None else 0.0)

        if extra_inertia is None:
            extra_inertia = float(red.stats.get("extra_inertia_coordinate", 0.0))
        return cls(inertia, torque, extra_inertia=extra_inertia, drive=drive, period=period,
                   coordinate=red.coordinate)

    @classmethod
    def from_transmission(cls, members: Sequence[Member], loads: Sequence[MemberLoad] = (),
                          drive=None, *, period: float = TWO_PI,
                          name: str = "transmission") -> ReducedMachine:
        """A machine given by the velocity ratios of its members (lecture notes §6).

        ``J_red = sum I_i r_i^2``, ``dJ_red/dphi = 2 sum I_i r_i r_i'``,
        ``M_red = sum M_j r_j + drive.torque_at(omega)``.  This is the honest way
        to reduce a belt drive or a gear train: mechdyn has no belt or gear-mesh
        joint, but their velocity ratios are exactly what the reduction needs.

        Parameters
        ----------
        members : sequence of Member
        loads : sequence of MemberLoad
        drive : object with ``torque_at(omega)``, optional
            A motor on the input (its ``extra_inertia()`` is added).
        """
        members = list(members)
        loads = list(loads)
        names = [m.name for m in members]
        if len(set(names)) != len(names):
            raise ModelError(f"transmission: member names must be unique, got {names}")

        def inertia(p):
            j = sum(m.inertia * _ratio(m.ratio, p) ** 2 for m in members)
            dj = sum(2.0 * m.inertia * _ratio(m.ratio, p) * _dratio(m, p) for m in members)
            return j, dj

        def torque(t, p, w):
            tot = 0.0
            for ld in loads:
                v = ld.value(t, p, w) if callable(ld.value) else ld.value
                tot += float(v) * _ratio(ld.ratio, p)
            if drive is not None:
                tot += float(drive.torque_at(w))
            return tot

        extra = float(drive.extra_inertia()) if hasattr(drive, "extra_inertia") else 0.0
        return cls(inertia, torque, extra_inertia=extra, drive=drive, period=period, name=name)

    @classmethod
    def constant(cls, inertia: float, torque: Callable | float, *, drive=None,
                 period: float = TWO_PI, name: str = "machine") -> ReducedMachine:
        """A machine of constant inertia (kg m^2) and torque ``torque(t, phi, omega)`` (N m)
        or a constant; a ``drive`` adds its ``torque_at(omega)``."""
        if not inertia > 0:
            raise ModelError(f"inertia must be > 0 kg*m^2, got {inertia!r}")
        j = float(inertia)

        def tq(t, p, w):
            v = torque(t, p, w) if callable(torque) else torque
            return float(v) + (float(drive.torque_at(w)) if drive is not None else 0.0)

        return cls(lambda p: (j, 0.0), tq, drive=drive, period=period, name=name)


def _single_drive(model: Model, coordinate: str):
    """The drive object on the coordinate (for reports), None if none or not a motor."""
    objs = [d.torque for d in model.mechanism.drives if d.coordinate == coordinate]
    objs = [o for o in objs if hasattr(o, "torque_at")]
    return objs[0] if len(objs) == 1 else None


class _SpeedDrives:
    """The drives on one coordinate as one ``torque_at(omega)`` (constants, characteristics)."""

    def __init__(self, parts):
        self.parts = list(parts)

    def torque_at(self, omega):
        tot = 0.0
        for p in self.parts:
            if hasattr(p, "torque_at"):
                tot += float(p.torque_at(omega))
            elif callable(p):
                tot += float(p(omega))
            else:
                tot += float(p)
        return tot


def _speed_drive(model: Model, coordinate: str):
    """The drives of a coordinate as a function of its speed only (None without drives)."""
    from ..mechanism.drive import TorqueSpeedCurve
    from ..mechanism.load import Table

    parts = []
    for d in model.mechanism.drives:
        if d.coordinate != coordinate:
            continue
        tq = d.torque
        if hasattr(tq, "torque_at") or isinstance(tq, TorqueSpeedCurve):
            parts.append(tq)
        elif isinstance(tq, Table) or callable(tq):
            raise ModelError(f"drive {d.name!r}: its torque depends on more than the speed of "
                             f"{coordinate!r}; use the exact machine "
                             f"(ReducedMachine.from_model, or --exact on the command line)")
        else:
            parts.append(float(tq))
    if not parts:
        return None
    if len(parts) == 1 and hasattr(parts[0], "torque_at"):
        return parts[0]
    return _SpeedDrives(parts)


def _nominal(drive) -> float | None:
    """A speed at which a drive runs near its rated point, rad/s (None if unknown)."""
    if drive is None:
        return None
    ratio = 1.0
    d = drive
    while hasattr(d, "ratio") and hasattr(d, "motor"):
        ratio *= d.ratio
        d = d.motor
    for attr in ("rated_speed", "speed"):
        v = getattr(d, attr, None)
        if v is not None:
            return float(v) / ratio
    v = getattr(d, "no_load_speed", None)
    if v is not None:
        return 0.5 * float(v) / ratio
    return None


# ============================================================================ time runs
@dataclass(frozen=True)
class ReducedRun:
    """A time history of the reduced machine.

    Attributes
    ----------
    t, phi, omega, epsilon : ndarray, shape (n,)
        Time (s), position (rad), speed (rad/s), acceleration (rad/s^2).
    J, M, M_drive : ndarray, shape (n,)
        Total reduced inertia (kg m^2), reduced torque and drive torque (N m).
    M_motor : ndarray or None
        Motor-side torque through a gear stage, N m.
    """

    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    J: np.ndarray
    M: np.ndarray
    M_drive: np.ndarray
    M_motor: np.ndarray | None = None
    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: dict = field(default_factory=dict)

    def to_dataframe(self):
        """Columns ``t_s, phi_deg, omega_rad_s, epsilon_rad_s2, J_kgm2, M_red_Nm, ...``."""
        import pandas as pd

        cols = {"t_s": self.t, "phi_deg": np.degrees(self.phi), "phi_rad": self.phi,
                "omega_rad_s": self.omega, "epsilon_rad_s2": self.epsilon,
                "J_total_kgm2": self.J, "M_red_Nm": self.M, "M_drive_Nm": self.M_drive}
        if self.M_motor is not None:
            cols["M_motor_Nm"] = self.M_motor
        return pd.DataFrame(cols)


def _history(machine: ReducedMachine, t, phi, omega, **kw) -> ReducedRun:
    n = t.size
    J = np.empty(n)
    M = np.empty(n)
    eps = np.empty(n)
    md = np.empty(n)
    mm = np.empty(n) if machine.drive is not None else None
    for i in range(n):
        j, dj = machine.inertia(phi[i])
        J[i] = j
        M[i] = machine.torque(t[i], phi[i], omega[i])
        eps[i] = (M[i] - 0.5 * dj * omega[i] ** 2) / j
        md[i] = machine.drive_torque(omega[i])
        if mm is not None:
            mm[i] = machine.motor_torque(omega[i])
    return ReducedRun(_frozen(t), _frozen(phi), _frozen(omega), _frozen(eps), _frozen(J),
                      _frozen(M), _frozen(md), None if mm is None else _frozen(mm), **kw)


def run_reduced(machine: ReducedMachine, t_end: float, *, phi0: float = 0.0,
                omega0: float = 0.0, t0: float = 0.0, integrator: str = "dop853",
                t_eval=None, events=None, **options) -> ReducedRun:
    """Integrate the reduced equation of motion in time.

    Parameters
    ----------
    machine : ReducedMachine
    t_end : float
        End time, s.
    phi0, omega0 : float
        Initial position (rad) and speed (rad/s).
    t0 : float
        Start time, s.
    integrator : str
        A name of :data:`mechdyn.integrate.INTEGRATORS` (``"wilson"``, ``"rk4"``,
        ``"dop853"``, ...).
    t_eval : array_like, optional
        Output times (default every step).
    events : optional
        Event functions ``g(t, q, qdot)`` (see :mod:`mechdyn.integrate.events`).
    **options
        Integrator options (``steps``/``dt`` for fixed-step ones; ``rtol``, ``atol``,
        ``max_step`` for the adaptive ones).

    Returns
    -------
    ReducedRun
    """
    from ..integrate import solve

    sol = solve(integrator, machine.rhs, t0, [phi0], [omega0], t_end, t_eval=t_eval,
                events=events, **options)
    return _history(machine, sol.t, sol.q[:, 0], sol.qdot[:, 0],
                    status="success" if sol.status == "success" else sol.status,
                    events=tuple(sol.events), stats=dict(sol.stats))


def energy_speed(machine: ReducedMachine, phi, *, phi0: float = 0.0, omega0: float,
                 t: float = 0.0, rtol: float = 1e-11) -> np.ndarray:
    """Speed from the energy form ``J omega^2/2 = J_0 omega_0^2/2 + int M dphi``.

    Valid when the reduced torque depends on the position only: it is evaluated
    at time ``t`` and speed ``omega0``.

    Parameters
    ----------
    phi : array_like, shape (n,)
        Positions, rad (any order, on either side of ``phi0``).
    phi0, omega0 : float
        Reference position (rad) and speed there (rad/s).

    Returns
    -------
    ndarray, shape (n,)
        omega(phi), rad/s; NaN where the kinetic energy would be negative (the
        machine cannot reach that position).
    """
    from scipy.integrate import solve_ivp

    phi = np.asarray(phi, dtype=float).reshape(-1)
    j0, _ = machine.inertia(phi0)
    out = np.empty_like(phi)
    for sign in (1.0, -1.0):
        sel = (phi >= phi0) if sign > 0 else (phi < phi0)
        if not np.any(sel):
            continue
        target = phi[sel]
        end = target.max() if sign > 0 else target.min()
        if end == phi0:
            w = np.zeros(target.size)
        else:
            sol = solve_ivp(lambda p, y: [machine.torque(t, p, omega0)], (phi0, end), [0.0],
                            method="DOP853", rtol=rtol, atol=1e-12 * max(1.0, j0 * omega0**2),
                            dense_output=True)
            w = sol.sol(target)[0]
        jt = np.array([machine.inertia(p)[0] for p in target])
        e2 = j0 * omega0**2 + 2.0 * w
        with np.errstate(invalid="ignore"):
            out[sel] = np.where(e2 >= 0, np.sqrt(np.maximum(e2, 0) / jt), np.nan)
    return out


# ============================================================================ steady cycle
@dataclass(frozen=True)
class SteadyCycle:
    """One cycle of the periodic steady motion of a reduced machine.

    Attributes
    ----------
    phi, t, omega, epsilon, J, M : ndarray, shape (n,)
        Position (rad, from ``phi0`` over one period), time from the cycle start
        (s), speed (rad/s), acceleration (rad/s^2), total inertia (kg m^2) and
        reduced torque (N m) on one cycle.
    omega_max, omega_min : float
        Extreme speeds, rad/s.
    omega_mean : float
        (omega_max + omega_min) / 2, rad/s: the mean of the coefficient of
        speed fluctuation and of the energy method.
    omega_avg : float
        True average speed, period / cycle time, rad/s.
    delta : float
        Coefficient of speed fluctuation (omega_max - omega_min) / omega_mean.
    cycle_time : float
        s.
    phi_at_max, phi_at_min : float
        Where the extremes occur, rad.
    """

    phi: np.ndarray
    t: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    J: np.ndarray
    M: np.ndarray
    omega_max: float
    omega_min: float
    omega_mean: float
    omega_avg: float
    delta: float
    cycle_time: float
    phi_at_max: float
    phi_at_min: float
    extra_inertia: float = 0.0
    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: dict = field(default_factory=dict)

    @property
    def delta_avg(self) -> float:
        """(omega_max - omega_min) / omega_avg, with the true average speed."""
        return (self.omega_max - self.omega_min) / self.omega_avg

    def to_dataframe(self):
        """Columns ``phi_deg, t_s, omega_rad_s, epsilon_rad_s2, J_total_kgm2, M_red_Nm``."""
        import pandas as pd

        return pd.DataFrame({"phi_deg": np.degrees(self.phi), "t_s": self.t,
                             "omega_rad_s": self.omega, "epsilon_rad_s2": self.epsilon,
                             "J_total_kgm2": self.J, "M_red_Nm": self.M})


class _Cycle:
    """One cycle integrated in the position with classical RK4 on a fixed grid.

    State (E, t) with E = J omega^2 / 2: dE/dphi = M_red(t, phi, omega),
    dt/dphi = 1/omega.  A fixed grid makes the cycle map omega0 -> omega_end a
    smooth deterministic function (shooting finds its fixed point exactly) and
    copes with loads that jump (punch windows); its error is O(h^4).
    """

    def __init__(self, machine: ReducedMachine, phi0: float, steps: int):
        self.m = machine
        self.phi0 = float(phi0)
        self.steps = int(steps)
        self.phi = self.phi0 + np.linspace(0.0, machine.period, self.steps + 1)
        self.h = machine.period / self.steps
        self.evaluations = 0

    def _f(self, p, e, t, e_floor):
        self.evaluations += 1
        j = self.m.inertia(p)[0]
        if e <= e_floor:
            raise LockupError(
                f"the machine stalls during the cycle at phi = {math.degrees(p):.4g} deg "
                f"(its speed drops to zero): the driving torque cannot carry the load through "
                f"the cycle at this speed; use startup() or start faster", q=[p])
        w = math.sqrt(2.0 * e / j)
        return self.m.torque(t, p, w), 1.0 / w

    def run(self, omega0: float, t0: float = 0.0, record: bool = False):
        """Integrate one cycle from speed ``omega0``; returns (omega_end, t_end, record)."""
        if not (math.isfinite(omega0) and omega0 > 0):
            raise IntegrationError(f"cycle start speed must be > 0 rad/s, got {omega0!r}")
        m, h, ph = self.m, self.h, self.phi
        e = 0.5 * m.inertia(ph[0])[0] * omega0 * omega0
        floor = 1e-10 * e
        t = float(t0)
        f = self._f
        if record:
            E = np.empty(self.steps + 1)
            T = np.empty(self.steps + 1)
            M = np.empty(self.steps + 1)
        for k in range(self.steps):
            p = ph[k]
            m1, r1 = f(p, e, t, floor)
            if record:
                E[k], T[k], M[k] = e, t, m1
            m2, r2 = f(p + 0.5 * h, e + 0.5 * h * m1, t + 0.5 * h * r1, floor)
            m3, r3 = f(p + 0.5 * h, e + 0.5 * h * m2, t + 0.5 * h * r2, floor)
            m4, r4 = f(ph[k + 1], e + h * m3, t + h * r3, floor)
            e += h * (m1 + 2.0 * m2 + 2.0 * m3 + m4) / 6.0
            t += h * (r1 + 2.0 * r2 + 2.0 * r3 + r4) / 6.0
        mend, _ = f(ph[-1], e, t, floor)
        w1 = math.sqrt(2.0 * e / m.inertia(ph[-1])[0])
        rec = None
        if record:
            E[-1], T[-1], M[-1] = e, t, mend
            rec = (E, T, M)
        return w1, t, rec


def _omega_of(machine, phi, E):
    J = np.array([machine.inertia(p)[0] for p in phi])
    return np.sqrt(2.0 * np.maximum(E, 0.0) / J), J


def steady_state(machine: ReducedMachine, *, omega_guess: float | None = None,
                 omega_mean: float | None = None, phi0: float = 0.0, t0: float = 0.0,
                 steps: int = 720, tol: float = 1e-10, max_iter: int = 60) -> SteadyCycle:
    """The periodic steady motion: shooting on the speed at ``phi0``.

    One cycle is integrated in the position (``dE/dphi = M_red`` with the kinetic
    energy ``E = J omega^2 / 2``, and ``dt/dphi = 1/omega``; classical RK4 with
    ``steps`` equal steps) and the speed at ``phi0`` is found for which it
    returns after one period, ``omega(phi0 + period) = omega(phi0)`` (a few
    fixed-point cycles, then the secant method).

    Parameters
    ----------
    machine : ReducedMachine
        Its torque must be periodic in phi (and may depend on omega and t).
    omega_guess : float, optional
        Start of the iteration, rad/s (default the drive's nominal speed, else
        the speed at which the mean torque over a cycle vanishes).
    omega_mean : float, optional
        For machines whose torque does not depend on the speed (a constant
        driving torque): the steady motions form a family, and this picks the
        one with (omega_max + omega_min)/2 = omega_mean (rad/s).  The cycle must
        then be balanced (zero net work), else no steady motion exists.
    phi0 : float
        Position where the cycle starts, rad.
    t0 : float
        Time at the cycle start, s (for time-dependent loads).
    steps : int
        RK4 steps per cycle (the cycle's samples are the steps' ends).
    tol : float
        Relative tolerance on the periodicity, |omega_end - omega_0| / omega_0.
    max_iter : int

    Returns
    -------
    SteadyCycle

    Raises
    ------
    LockupError
        The machine stalls within a cycle.
    IntegrationError
        No periodic motion was found (the message gives the change of speed over
        a cycle).
    """
    from scipy.optimize import brentq

    if int(steps) < 8:
        raise ModelError(f"steps must be at least 8, got {steps!r}")
    cyc = _Cycle(machine, phi0, steps)
    iters = 0

    def g(w0):
        nonlocal iters
        iters += 1
        w1, _, _ = cyc.run(w0, t0)
        return w1 - w0, w1

    if omega_mean is not None:
        target = float(omega_mean)
        if not target > 0:
            raise ModelError(f"omega_mean must be > 0 rad/s, got {omega_mean!r}")

        def mean_err(w0):
            _, _, (E, _, _) = cyc.run(w0, t0, record=True)
            om, _ = _omega_of(machine, cyc.phi, E)
            return 0.5 * (om.max() + om.min()) - target

        lo = hi = target
        flo = mean_err(lo)
        if flo == 0:
            w0 = lo
        else:
            step = 1.05 if flo < 0 else 1 / 1.05
            for _ in range(200):
                hi = hi * step
                try:
                    fhi = mean_err(hi)
                except LockupError:
                    continue
                if np.sign(fhi) != np.sign(flo):
                    break
            else:
                raise IntegrationError(f"no cycle with mean speed {target:.6g} rad/s found")
            w0 = brentq(mean_err, min(lo, hi), max(lo, hi), xtol=1e-13 * target,
                        rtol=4 * np.finfo(float).eps)
        err, _ = g(w0)
        if abs(err) > max(tol, 1e-8) * w0:
            raise IntegrationError(
                f"the machine has no steady motion at mean speed {target:.6g} rad/s: over one "
                f"cycle its speed changes by {err:.6g} rad/s (the work of the driving torque "
                f"does not balance the load); balance the mean torque or use a speed-dependent "
                f"drive")
        return _finish(machine, cyc, w0, t0, iters)

    w0 = omega_guess if omega_guess is not None else machine.nominal_speed
    if w0 is None:
        w0 = _balance_speed(machine, t0, phi0)
    if not w0 > 0:
        raise ModelError(f"omega_guess must be > 0 rad/s, got {w0!r}")
    w0 = float(w0)
    # a few fixed-point cycles (the motor's slope makes the map contracting) ...
    for _ in range(3):
        err, w1 = g(w0)
        if abs(err) <= tol * w0:
            return _finish(machine, cyc, w0, t0, iters)
        w0 = w1
    # ... then the secant method on g(omega0) = omega_end - omega0
    wa = w0
    ea, _ = g(wa)
    wb = wa * (1.0 + 1e-3)
    eb, _ = g(wb)
    for _ in range(max_iter):
        if abs(eb) <= tol * wb:
            return _finish(machine, cyc, wb, t0, iters)
        if eb == ea:
            break
        wc = wb - eb * (wb - wa) / (eb - ea)
        if not wc > 0:
            wc = 0.5 * wb
        wa, ea = wb, eb
        wb = wc
        eb, _ = g(wb)
    raise IntegrationError(
        f"no periodic steady motion found after {iters} cycles (last omega0 = {wb:.6g} rad/s, "
        f"change over a cycle {eb:.3g} rad/s); a machine with a speed-independent drive needs "
        f"omega_mean=..., and the mean driving torque must balance the load")


def _balance_speed(machine: ReducedMachine, t0: float, phi0: float) -> float:
    """Speed (rad/s) at which the torque averaged over a cycle at constant speed vanishes."""
    from scipy.optimize import brentq

    ph = phi0 + np.linspace(0.0, machine.period, 73)[:-1]

    def mean_torque(w):
        return float(np.mean([machine.torque(t0, p, w) for p in ph]))

    ws = np.geomspace(1e-2, 1e5, 71)
    vals = np.array([mean_torque(w) for w in ws])
    tol = 1e-9 * max(float(np.max(np.abs(vals))), 1e-300)
    for k in range(len(ws) - 1):
        if vals[k] > tol and vals[k + 1] <= tol:
            lo, hi = ws[k], ws[k + 1]
            if vals[k + 1] < -tol:
                return brentq(mean_torque, lo, hi, rtol=1e-10)
            for _ in range(80):  # the torque vanishes from some speed on: its first zero
                mid = 0.5 * (lo + hi)
                if mean_torque(mid) > tol:
                    lo = mid
                else:
                    hi = mid
            return hi
    raise ModelError("steady_state needs omega_guess (rad/s): no speed between 0.01 and 1e5 "
                     "rad/s balances the mean torque over a cycle")


def _finish(machine, cyc: _Cycle, w0, t0, iters) -> SteadyCycle:
    from scipy.optimize import minimize_scalar

    _, t1, (E, T, M) = cyc.run(w0, t0, record=True)
    ph = cyc.phi
    om, J = _omega_of(machine, ph, E)
    dJ = np.array([machine.inertia(p)[1] for p in ph])
    eps = (M - 0.5 * dJ * om**2) / J
    h = cyc.h

    # refine the extremes between the samples: cubic Hermite of E (dE/dphi = M)
    def speed(p, k):
        u = (p - ph[k]) / h
        h00, h10 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u
        h01, h11 = -2 * u**3 + 3 * u**2, u**3 - u**2
        e = h00 * E[k] + h10 * h * M[k] + h01 * E[k + 1] + h11 * h * M[k + 1]
        return math.sqrt(2.0 * max(e, 0.0) / machine.inertia(p)[0])

    ext = []
    for k0, sign in ((int(np.argmax(om)), -1.0), (int(np.argmin(om)), 1.0)):
        best = (sign * om[k0], ph[k0])
        for k in (k0 - 1, k0):
            if 0 <= k < cyc.steps:
                r = minimize_scalar(lambda p, k=k, s=sign: s * speed(p, k),
                                    bounds=(ph[k], ph[k + 1]), method="bounded",
                                    options={"xatol": 1e-12})
                best = min(best, (float(r.fun), float(r.x)))
        ext.append((sign * best[0], best[1]))
    (wmax, pmax), (wmin, pmin) = ext
    wmean = 0.5 * (wmax + wmin)
    T_cyc = t1 - t0
    return SteadyCycle(
        phi=_frozen(ph), t=_frozen(T - t0), omega=_frozen(om), epsilon=_frozen(eps),
        J=_frozen(J), M=_frozen(M), omega_max=float(wmax), omega_min=float(wmin),
        omega_mean=float(wmean), omega_avg=float(machine.period / T_cyc),
        delta=float((wmax - wmin) / wmean), cycle_time=float(T_cyc), phi_at_max=float(pmax),
        phi_at_min=float(pmin), extra_inertia=machine.extra_inertia,
        stats={"cycles_integrated": iters + 1, "evaluations": cyc.evaluations,
               "omega0": float(w0), "steps": cyc.steps})


# ============================================================================ flywheel
@dataclass(frozen=True)
class FlywheelSizing:
    """A flywheel for a target coefficient of speed fluctuation.

    Attributes
    ----------
    delta_target : float
    omega_mean : float
        Mean speed of the link of reduction, rad/s.
    delta_E_max : float
        Largest swing of the work of the reduced torque over a cycle, J
        (``max W - min W`` with the torque at omega_mean, balanced).
    delta_E_refined : float
        The same for the work minus the kinetic energy of the variable part of
        J_red at omega_mean, J (refined energy method).
    J_red_mean, J_red_min, J_red_max : float
        Of the machine without the flywheel (drive inertia included), kg m^2.
    J_fly_energy : float
        ``delta_E_max / (delta omega_mean^2) - J_red_mean``, kg m^2 (basic energy method).
    J_fly_refined : float
        ``delta_E_refined / (delta omega_mean^2) - J_red_mean``, kg m^2.
    J_fly : float
        The recommended flywheel on the link of reduction (method ``method``),
        kg m^2; 0 when the machine already meets the target.
    J_fly_motor : float or None
        The same on the motor shaft through the gear, ``J_fly / i^2``, kg m^2.
    gear_ratio : float or None
    delta_simulated : float or None
        Coefficient of fluctuation of the steady cycle with ``J_fly`` added.
    delta_without : float or None
        Of the steady cycle without a flywheel.
    method : str
    cycle : SteadyCycle or None
        The steady cycle with the flywheel.
    """

    delta_target: float
    omega_mean: float
    delta_E_max: float
    delta_E_refined: float
    J_red_mean: float
    J_red_min: float
    J_red_max: float
    J_fly_energy: float
    J_fly_refined: float
    J_fly: float
    J_fly_motor: float | None
    gear_ratio: float | None
    delta_simulated: float | None
    delta_without: float | None
    method: str
    cycle: SteadyCycle | None = None
    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: dict = field(default_factory=dict)

    def to_dataframe(self):
        """One row of the sizing figures with unit-suffixed columns."""
        import pandas as pd

        return pd.DataFrame([{
            "delta_target": self.delta_target, "omega_mean_rad_s": self.omega_mean,
            "delta_E_max_J": self.delta_E_max, "delta_E_refined_J": self.delta_E_refined,
            "J_red_mean_kgm2": self.J_red_mean, "J_fly_energy_kgm2": self.J_fly_energy,
            "J_fly_refined_kgm2": self.J_fly_refined, "J_fly_kgm2": self.J_fly,
            "J_fly_motor_kgm2": self.J_fly_motor, "gear_ratio": self.gear_ratio,
            "delta_simulated": self.delta_simulated, "delta_without": self.delta_without,
            "method": self.method}])


FLYWHEEL_METHODS = ("energy", "refined", "simulation")


def size_flywheel(machine: ReducedMachine, delta: float, *, omega_mean: float | None = None,
                  omega_guess: float | None = None, gear_ratio: float | None = None,
                  method: str = "refined", confirm: bool = True, phi0: float = 0.0,
                  t: float = 0.0, points: int = 2001, rtol: float = 1e-3) -> FlywheelSizing:
    """Size a flywheel for a coefficient of speed fluctuation ``delta``.

    Energy method: with the work ``W(phi) = int (M_red at omega_mean) dphi`` of one
    cycle (its mean torque removed so the cycle balances), the kinetic energy
    swings by ``Delta E_max = max W - min W``; as ``(J/2)(omega_max^2 -
    omega_min^2) = J delta omega_mean^2`` with ``omega_mean = (omega_max +
    omega_min)/2``, the constant inertia needed is ``Delta E_max / (delta
    omega_mean^2)``, exact for a constant J and a torque of the position only.
    The basic form then subtracts the mean reduced inertia; the refined form
    subtracts from W the kinetic energy of the variable part of J_red,
    ``(J_red - J_red_mean) omega_mean^2 / 2``, before taking the swing.
    ``method="simulation"`` starts from the refined value and corrects it
    (secant) until the simulated steady cycle meets ``delta`` within ``rtol``.

    Parameters
    ----------
    machine : ReducedMachine
    delta : float
        Target (omega_max - omega_min)/omega_mean, in (0, 2).
    omega_mean : float, optional
        Mean speed, rad/s; default from the steady cycle without a flywheel
        (needs a speed-dependent drive).
    omega_guess : float, optional
        Start of the steady-state iteration, rad/s.
    gear_ratio : float, optional
        i = omega_motor / omega_link, to report the flywheel on the motor shaft
        (``J_fly / i^2``); default the machine's gear stage ratio if any.
    method : {"energy", "refined", "simulation"}
    confirm : bool
        Simulate the steady cycle with the flywheel and report its delta.
    phi0 : float
        Cycle start, rad.
    t : float
        Time at which the torque is evaluated for the energy method, s.
    points : int
        Positions for the work integral.
    rtol : float
        Relative tolerance on delta for ``method="simulation"``.

    Returns
    -------
    FlywheelSizing
    """
    from scipy.integrate import cumulative_simpson

    if not (isinstance(delta, (int, float)) and 0 < delta < 2):
        raise ModelError(f"delta (coefficient of speed fluctuation) must lie in (0, 2), "
                         f"got {delta!r}")
    if method not in FLYWHEEL_METHODS:
        raise ModelError(f"method must be one of {', '.join(map(repr, FLYWHEEL_METHODS))}, "
                         f"got {method!r}")
    dependent = machine.speed_dependent(t)
    if omega_mean is None:
        if not dependent:
            raise ModelError("the reduced torque does not depend on the speed, so the machine "
                             "does not choose its steady speed: give omega_mean")
        base = steady_state(machine, omega_guess=omega_guess, phi0=phi0)
        omega_mean = base.omega_mean
    elif dependent:
        base = steady_state(machine, omega_guess=omega_mean, phi0=phi0)
    else:
        base = steady_state(machine, omega_mean=omega_mean, phi0=phi0)
    wm = float(omega_mean)
    if not wm > 0:
        raise ModelError(f"omega_mean must be > 0 rad/s, got {omega_mean!r}")
    if gear_ratio is None:
        gear_ratio = getattr(machine.drive, "ratio", None)
    ph = phi0 + np.linspace(0.0, machine.period, int(points))
    M = np.array([machine.torque(t, p, wm) for p in ph])
    J = np.array([machine.inertia(p)[0] for p in ph])
    imbalance = float(np.mean(M[:-1]))  # mean torque over the cycle (uniform grid)
    Mb = M - imbalance
    W = cumulative_simpson(Mb, x=ph, initial=0.0)
    W -= (W[-1] / machine.period) * (ph - ph[0])  # remove the residual quadrature drift
    dE = float(W.max() - W.min())
    jm = float(np.mean(J[:-1]))
    E2 = (J - jm) * wm * wm / 2.0
    WI = W - E2
    dE_ref = float(WI.max() - WI.min())
    need = 1.0 / (delta * wm * wm)
    j_basic = dE * need - jm
    j_ref = dE_ref * need - jm
    j_fly = j_basic if method == "energy" else j_ref
    msgs = []
    if abs(imbalance) > 0.02 * max(1e-300, float(np.max(np.abs(M)))):
        msgs.append(f"the mean torque at omega_mean is {imbalance:.4g} N m (the cycle is not "
                    f"balanced at this speed); it was removed for the energy method")
    if j_fly < 0:
        msgs.append(f"the machine's own inertia meets delta = {delta:g} (the estimate is "
                    f"{j_fly:.4g} kg m^2): no flywheel is needed")
        j_fly = 0.0
    cycle = None
    d_sim = None
    kw = {"omega_guess": wm} if dependent else {"omega_mean": wm}
    if method == "simulation":
        def dsim(jf):
            c = steady_state(machine.with_extra_inertia(jf), phi0=phi0, **kw)
            return c.delta, c

        # 1/delta is nearly linear in the total inertia: secant on 1/delta - 1/target
        ja = max(j_fly, 0.0)
        da, cycle = dsim(ja)
        jb, db = ja, da
        if abs(da / delta - 1.0) > rtol:
            jb = max(ja + (ja + jm) * (da / delta - 1.0), 0.0)
            db, cycle = dsim(jb)
            for _ in range(30):
                if abs(db / delta - 1.0) <= rtol or db == da:
                    break
                jc = jb + (1 / delta - 1 / db) * (jb - ja) / (1 / db - 1 / da)
                ja, da = jb, db
                jb = max(jc, 0.0)
                db, cycle = dsim(jb)
                if jb == 0.0 and db < delta:
                    break
        j_fly, d_sim = jb, db
    elif confirm:
        cycle = steady_state(machine.with_extra_inertia(j_fly), phi0=phi0, **kw)
        d_sim = cycle.delta
    if d_sim is not None and abs(d_sim / delta - 1.0) > 0.05 and j_fly > 0:
        msgs.append(f"the simulated delta {d_sim:.4g} differs from the target by "
                    f"{100 * (d_sim / delta - 1):.1f} %: the energy method's assumptions "
                    f"(torque independent of the speed, small fluctuation) do not hold well; "
                    f"use method='simulation'")
    d0 = base.delta
    j_motor = None if gear_ratio is None else j_fly / float(gear_ratio) ** 2
    return FlywheelSizing(
        delta_target=float(delta), omega_mean=wm, delta_E_max=dE, delta_E_refined=dE_ref,
        J_red_mean=jm, J_red_min=float(J.min()), J_red_max=float(J.max()),
        J_fly_energy=float(j_basic), J_fly_refined=float(j_ref), J_fly=float(j_fly),
        J_fly_motor=j_motor, gear_ratio=None if gear_ratio is None else float(gear_ratio),
        delta_simulated=d_sim, delta_without=d0, method=method, cycle=cycle,
        message="; ".join(msgs), stats={"mean_torque_removed_Nm": imbalance})


# ============================================================================ start-up
@dataclass(frozen=True)
class StartupResult:
    """Start-up of a machine from rest by its motor, and its steady regime.

    Attributes
    ----------
    run : ReducedRun
        The time history (t, phi, omega, torques).
    steady : SteadyCycle
        The steady cycle the run approaches.
    t_steady : float or None
        First time after which the speed stays within ``tol * omega_mean`` of the
        steady cycle at the same position, s (None if not reached by t_end).
    peak_drive_torque : float
        Largest drive torque on the link during the run, N m.
    peak_motor_torque : float or None
        Largest motor-side torque (through the gear stage), N m.
    speed_dip : float
        omega_max - omega_min of the steady cycle, rad/s (the dip when the load
        acts, or between ``load_window`` start and the minimum after it).
    phi_dip : float
        Position of the minimum speed of the steady cycle, rad.
    omega_mean : float
        Mean speed of the steady cycle, rad/s.
    """

    run: ReducedRun
    steady: SteadyCycle
    t_steady: float | None
    peak_drive_torque: float
    peak_motor_torque: float | None
    speed_dip: float
    phi_dip: float
    omega_mean: float
    tol: float
    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: dict = field(default_factory=dict)

    def to_dataframe(self):
        """The run's time history (see :meth:`ReducedRun.to_dataframe`)."""
        return self.run.to_dataframe()

    def summary(self) -> dict:
        """The headline figures in SI units."""
        return {"t_steady_s": self.t_steady, "peak_drive_torque_Nm": self.peak_drive_torque,
                "peak_motor_torque_Nm": self.peak_motor_torque,
                "omega_mean_rad_s": self.omega_mean, "speed_dip_rad_s": self.speed_dip,
                "phi_dip_deg": math.degrees(self.phi_dip), "delta": self.steady.delta}


def startup(machine: ReducedMachine, t_end: float, *, phi0: float = 0.0, omega0: float = 0.0,
            tol: float = 0.01, load_window: tuple[float, float] | None = None,
            samples_per_second: float = 4000.0, integrator: str = "dop853",
            steady: SteadyCycle | None = None, **options) -> StartupResult:
    """Start the machine from rest (or ``omega0``) and measure the transient.

    Parameters
    ----------
    machine : ReducedMachine
        With a speed-dependent drive (a motor).
    t_end : float
        Length of the run, s.
    phi0, omega0 : float
        Initial position (rad) and speed (rad/s).
    tol : float
        Band around the steady cycle, as a fraction of its mean speed, that
        defines "steady".
    load_window : (float, float), optional
        Positions (rad, within one period) where the working load acts; the speed
        dip is then measured from the speed at the window start to the minimum
        after it.  Default: omega_max - omega_min of the steady cycle.
    samples_per_second : float
        Output sampling, 1/s.
    integrator : str
        As for :func:`run_reduced` (options passed on).
    steady : SteadyCycle, optional
        A steady cycle computed before (else found here).

    Returns
    -------
    StartupResult
    """
    if not t_end > 0:
        raise ModelError(f"t_end must be > 0 s, got {t_end!r}")
    te = np.linspace(0.0, float(t_end), max(2, int(samples_per_second * t_end) + 1))
    run = run_reduced(machine, t_end, phi0=phi0, omega0=omega0, integrator=integrator,
                      t_eval=te, **options)
    if steady is None:
        steady = steady_state(machine, omega_guess=max(run.omega[-1], 1e-6), phi0=phi0)
    # deviation from the steady cycle at the same position
    per = machine.period
    u = steady.phi[0] + (run.phi - steady.phi[0]) % per
    ref = np.interp(u, steady.phi, steady.omega)
    dev = np.abs(run.omega - ref) / steady.omega_mean
    outside = np.flatnonzero(dev > tol)
    if outside.size == 0:
        t_steady = float(run.t[0])
    elif outside[-1] == run.t.size - 1:
        t_steady = None
    else:
        t_steady = float(run.t[outside[-1] + 1])
    if load_window is None:
        dip = steady.omega_max - steady.omega_min
        phi_dip = steady.phi_at_min
    else:
        a, b = load_window
        pa = steady.phi[0] + (a - steady.phi[0]) % per
        w_a = float(np.interp(pa, steady.phi, steady.omega))
        pb = pa + ((b - a) % per) + 0.5 * per  # the minimum may come after the window
        grid = np.linspace(pa, pb, 721)
        w = np.interp(steady.phi[0] + (grid - steady.phi[0]) % per, steady.phi, steady.omega)
        k = int(np.argmin(w))
        dip = w_a - float(w[k])
        phi_dip = float(steady.phi[0] + (grid[k] - steady.phi[0]) % per)
    msg = "" if t_steady is not None else (f"the speed has not settled within {tol:.3g} of "
                                           f"the steady cycle by t = {t_end:g} s")
    pm = None if run.M_motor is None else float(np.max(run.M_motor))
    return StartupResult(run=run, steady=steady, t_steady=t_steady,
                         peak_drive_torque=float(np.max(run.M_drive)), peak_motor_torque=pm,
                         speed_dip=float(dip), phi_dip=float(phi_dip),
                         omega_mean=steady.omega_mean, tol=float(tol),
                         status="success" if t_steady is not None else "not_settled",
                         message=msg, stats=dict(run.stats))

