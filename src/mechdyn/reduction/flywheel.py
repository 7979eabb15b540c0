"""The periodic steady motion of a reduced machine and flywheel sizing.

Public names
------------
SteadyCycle, steady_state
    The periodic steady motion (shooting on omega at phi0) and its coefficient
    of speed fluctuation.
FlywheelSizing, size_flywheel
    Flywheel sizing by the energy method (basic and refined), confirmed or
    corrected by simulating the steady cycle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..brief import brief, number, status_text
from ..errors import IntegrationError, LockupError, ModelError
from ..results.records import FlywheelStats, SteadyCycleStats
from .machine import ReducedMachine, _Motion, _Record

__all__ = ["SteadyCycle", "steady_state", "FlywheelSizing", "size_flywheel", "FLYWHEEL_METHODS"]

#: RK4 steps over one cycle of the steady-state shooting (and of the balance of a
#: machine without a drive, in the same quadrature)
CYCLE_STEPS = 720


# ============================================================================ steady cycle
@dataclass(frozen=True, repr=False)
class SteadyCycle(_Motion):
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

    omega_max: float
    omega_min: float
    omega_mean: float
    omega_avg: float
    delta: float
    cycle_time: float
    phi_at_max: float
    phi_at_min: float
    extra_inertia: float = 0.0

    def _figures(self) -> tuple[str, ...]:
        return (f"omega_mean {number(self.omega_mean, 'rad/s')}",
                f"delta {number(self.delta)}", f"cycle {number(self.cycle_time, 's')}")

    @property
    def delta_avg(self) -> float:
        """(omega_max - omega_min) / omega_avg, with the true average speed."""
        return (self.omega_max - self.omega_min) / self.omega_avg


def _cycle(machine: ReducedMachine, ph: np.ndarray, omega0: float, t0: float, calls: list):
    """One cycle from speed ``omega0`` over the grid ``ph``: (omega_end, E, t, M on the grid).

    Classical RK4 in the position on the state (E, t) with E = J omega^2 / 2:
    dE/dphi = M_red(t, phi, omega), dt/dphi = 1/omega.  A fixed grid makes the cycle
    map omega0 -> omega_end a smooth deterministic function (shooting finds its fixed
    point exactly) and copes with loads that jump (punch windows); its error is O(h^4).
    ``calls[0]`` counts the machine's evaluations.
    """
    if not (math.isfinite(omega0) and omega0 > 0):
        raise IntegrationError(f"cycle start speed must be > 0 rad/s, got {omega0!r}")
    h = machine.period / (ph.size - 1)
    E, T, M = np.empty(ph.size), np.empty(ph.size), np.empty(ph.size)
    e = 0.5 * machine.inertia(ph[0])[0] * omega0 * omega0
    floor = 1e-10 * e

    def f(p, e, t):
        calls[0] += 1
        j = machine.inertia(p)[0]
        if e <= floor:
            raise LockupError(
                f"the machine stalls during the cycle at phi = {math.degrees(p):.4g} deg "
                f"(its speed drops to zero): the driving torque cannot carry the load through "
                f"the cycle at this speed; use startup() or start faster", q=[p])
        w = math.sqrt(2.0 * e / j)
        return machine.torque(t, p, w), 1.0 / w

    t = float(t0)
    for k in range(ph.size - 1):
        p = ph[k]
        m1, r1 = f(p, e, t)
        E[k], T[k], M[k] = e, t, m1
        m2, r2 = f(p + 0.5 * h, e + 0.5 * h * m1, t + 0.5 * h * r1)
        m3, r3 = f(p + 0.5 * h, e + 0.5 * h * m2, t + 0.5 * h * r2)
        m4, r4 = f(ph[k + 1], e + h * m3, t + h * r3)
        e += h * (m1 + 2.0 * m2 + 2.0 * m3 + m4) / 6.0
        t += h * (r1 + 2.0 * r2 + 2.0 * r3 + r4) / 6.0
    E[-1], T[-1] = e, t
    M[-1], _ = f(ph[-1], e, t)
    return math.sqrt(2.0 * e / machine.inertia(ph[-1])[0]), E, T, M


def steady_state(machine: ReducedMachine, *, omega_guess: float | None = None,
                 omega_mean: float | None = None, phi0: float = 0.0, t0: float = 0.0,
                 steps: int = CYCLE_STEPS, tol: float = 1e-10,
                 max_iter: int = 60) -> SteadyCycle:
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
    ph = float(phi0) + np.linspace(0.0, machine.period, int(steps) + 1)
    calls = [0]
    iters = 0

    def g(w0):
        nonlocal iters
        iters += 1
        w1 = _cycle(machine, ph, w0, t0, calls)[0]
        return w1 - w0, w1

    if omega_mean is not None:
        target = float(omega_mean)
        if not target > 0:
            raise ModelError(f"omega_mean must be > 0 rad/s, got {omega_mean!r}")

        def mean_err(w0):
            E = _cycle(machine, ph, w0, t0, calls)[1]
            om = np.sqrt(2.0 * np.maximum(E, 0.0) / machine.inertia_along(ph))
            return 0.5 * (om.max() + om.min()) - target

        lo = hi = target
        flo = mean_err(lo)
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
        return _finish(machine, ph, calls, w0, t0, iters)

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
            return _finish(machine, ph, calls, w0, t0, iters)
        w0 = w1
    # ... then the secant method on g(omega0) = omega_end - omega0
    wa = w0
    ea, _ = g(wa)
    wb = wa * (1.0 + 1e-3)
    eb, _ = g(wb)
    for _ in range(max_iter):
        if abs(eb) <= tol * wb:
            return _finish(machine, ph, calls, wb, t0, iters)
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
        if vals[k] > tol and vals[k + 1] <= tol:  # the first speed where it vanishes
            return brentq(lambda w: mean_torque(w) - tol, ws[k], ws[k + 1], rtol=1e-10)
    raise ModelError("steady_state needs omega_guess (rad/s): no speed between 0.01 and 1e5 "
                     "rad/s balances the mean torque over a cycle")


def _finish(machine, ph, calls, w0, t0, iters) -> SteadyCycle:
    from scipy.interpolate import CubicHermiteSpline
    from scipy.optimize import minimize_scalar

    _, E, T, M = _cycle(machine, ph, w0, t0, calls)
    J, dJ = np.array([machine.inertia(p) for p in ph]).T
    om = np.sqrt(2.0 * np.maximum(E, 0.0) / J)
    eps = (M - 0.5 * dJ * om**2) / J
    energy = CubicHermiteSpline(ph, E, M)  # E between the samples (dE/dphi = M)

    def speed(p):
        return math.sqrt(2.0 * max(float(energy(p)), 0.0) / machine.inertia(p)[0])

    ext = []  # the extremes refined between the samples
    for k0, sign in ((int(np.argmax(om)), -1.0), (int(np.argmin(om)), 1.0)):
        best = (sign * om[k0], ph[k0])
        for k in (k0 - 1, k0):
            if 0 <= k < ph.size - 1:
                r = minimize_scalar(lambda p, s=sign: s * speed(p), bounds=(ph[k], ph[k + 1]),
                                    method="bounded", options={"xatol": 1e-12})
                best = min(best, (float(r.fun), float(r.x)))
        ext.append((sign * best[0], best[1]))
    (wmax, pmax), (wmin, pmin) = ext
    wmean = 0.5 * (wmax + wmin)
    T_cyc = T[-1] - t0
    return SteadyCycle(
        phi=ph, t=T - t0, omega=om, epsilon=eps, J=J, M=M, omega_max=float(wmax),
        omega_min=float(wmin), omega_mean=float(wmean), omega_avg=float(machine.period / T_cyc),
        delta=float((wmax - wmin) / wmean), cycle_time=float(T_cyc), phi_at_max=float(pmax),
        phi_at_min=float(pmin), extra_inertia=machine.extra_inertia,
        stats=SteadyCycleStats(cycles_integrated=iters + 1, evaluations=calls[0],
                               omega0=float(w0), steps=ph.size - 1))


# ============================================================================ flywheel
@dataclass(frozen=True, repr=False)
class FlywheelSizing(_Record):
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

    def __repr__(self) -> str:
        motor = f"J_fly_motor {number(self.J_fly_motor, 'kg m^2')}" \
            if self.J_fly_motor is not None else ""
        return brief(self, f"method {self.method!r}", status_text(self),
                     f"delta {number(self.delta_target)}",
                     f"omega_mean {number(self.omega_mean, 'rad/s')}",
                     f"J_fly {number(self.J_fly, 'kg m^2')}", motor,
                     f"delta_E_max {number(self.delta_E_max, 'J')}")

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
                  method: str | None = None, confirm: bool = True, phi0: float = 0.0,
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
    When the steady cycle without a flywheel already meets ``delta``, the answer is
    zero whatever the method (the energy estimates are still reported beside it).

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
    method : {"energy", "refined", "simulation"}, optional
        Default ``"simulation"`` when the reduced torque depends on the speed (a motor:
        its slope smooths the speed, which the energy method does not see), else
        ``"refined"``.
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
    from scipy.integrate import cumulative_simpson, simpson

    if not (isinstance(delta, (int, float)) and 0 < delta < 2):
        raise ModelError(f"delta (coefficient of speed fluctuation) must lie in (0, 2), "
                         f"got {delta!r}")
    dependent = machine.speed_dependent(t)
    if method is None:
        method = "simulation" if dependent else "refined"
    if method not in FLYWHEEL_METHODS:
        raise ModelError(f"method must be one of {', '.join(map(repr, FLYWHEEL_METHODS))}, "
                         f"got {method!r}")
    base = None
    if omega_mean is None:
        if not dependent:
            raise ModelError("the reduced torque does not depend on the speed, so the machine "
                             "does not choose its steady speed: give omega_mean")
        base = steady_state(machine, omega_guess=omega_guess, phi0=phi0)
        omega_mean = base.omega_mean
    wm = float(omega_mean)
    if not wm > 0:
        raise ModelError(f"omega_mean must be > 0 rad/s, got {omega_mean!r}")
    msgs = []
    if machine.drive is None and not dependent:
        # no drive: the classic energy method's drive, a constant torque equal to the mean
        # of the load torque, keeps the mean speed.  Simpson's rule on the steady cycle's
        # own grid (RK4 in phi of a torque of phi alone is Simpson's rule), so that the
        # cycle balances in its quadrature too
        ph_ = phi0 + np.linspace(0.0, machine.period, 2 * CYCLE_STEPS + 1)
        load = float(simpson([machine.torque(t, p, wm) for p in ph_], x=ph_)) / machine.period
        machine = machine.with_driving_torque(-load)
        msgs.append(f"the model has no drive: a constant driving torque of {-load:.6g} N m "
                    f"(the mean of the load torque) keeps the mean speed (classic energy "
                    f"method)")
    kw = {"omega_guess": wm} if dependent else {"omega_mean": wm}
    stall = None
    if base is None:
        try:
            base = steady_state(machine, phi0=phi0, **kw)
        except LockupError as exc:  # without a flywheel the machine cannot keep this speed
            if dependent:
                raise
            stall = str(exc)
    if gear_ratio is None:
        gear_ratio = getattr(machine.drive, "ratio", None)
    ph = phi0 + np.linspace(0.0, machine.period, int(points))
    M = np.array([machine.torque(t, p, wm) for p in ph])
    J = machine.inertia_along(ph)
    imbalance = float(np.mean(M[:-1]))  # mean torque over the cycle (uniform grid)
    W = cumulative_simpson(M - imbalance, x=ph, initial=0.0)
    W -= (W[-1] / machine.period) * (ph - ph[0])  # remove the residual quadrature drift
    dE = float(W.max() - W.min())
    jm = float(np.mean(J[:-1]))
    WI = W - (J - jm) * wm * wm / 2.0  # less the kinetic energy of the variable part of J
    dE_ref = float(WI.max() - WI.min())
    need = 1.0 / (delta * wm * wm)
    j_basic = dE * need - jm
    j_ref = dE_ref * need - jm
    j_fly = j_basic if method == "energy" else j_ref
    if abs(imbalance) > 0.02 * max(1e-300, float(np.max(np.abs(M)))):
        msgs.append(f"the mean torque at omega_mean is {imbalance:.4g} N m (the cycle is not "
                    f"balanced at this speed); it was removed for the energy method")
    met = base is not None and base.delta <= delta  # the machine as it is meets the target
    if j_fly < 0 and not met:
        msgs.append(f"the machine's own inertia meets delta = {delta:g} (the estimate is "
                    f"{j_fly:.4g} kg m^2): no flywheel is needed")
    j_fly = max(j_fly, 0.0)
    cycle = d_sim = None
    if stall is not None:
        msgs.append(f"without a flywheel the machine cannot keep the mean speed ({stall})")

    def dsim(jf):
        c = steady_state(machine.with_extra_inertia(jf), phi0=phi0, **kw)
        return c.delta, c

    if met:
        msgs.append(f"the steady cycle without a flywheel has delta = {base.delta:.4g} <= "
                    f"{delta:g}: no flywheel is needed (energy estimates: {j_basic:.4g}, "
                    f"refined {j_ref:.4g} kg m^2)")
        j_fly, cycle, d_sim = 0.0, base, base.delta
    elif method == "simulation":
        # 1/delta is nearly linear in the total inertia: secant on 1/delta - 1/target
        ja = j_fly
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
        d_sim, cycle = dsim(j_fly)
    if d_sim is not None and abs(d_sim / delta - 1.0) > 0.05 and j_fly > 0:
        msgs.append(f"the simulated delta {d_sim:.4g} differs from the target by "
                    f"{100 * (d_sim / delta - 1):.1f} %: the energy method's assumptions "
                    f"(torque independent of the speed, small fluctuation) do not hold well; "
                    f"use method='simulation'")
    d0 = None if base is None else base.delta
    j_motor = None if gear_ratio is None else j_fly / float(gear_ratio) ** 2
    return FlywheelSizing(
        delta_target=float(delta), omega_mean=wm, delta_E_max=dE, delta_E_refined=dE_ref,
        J_red_mean=jm, J_red_min=float(J.min()), J_red_max=float(J.max()),
        J_fly_energy=float(j_basic), J_fly_refined=float(j_ref), J_fly=float(j_fly),
        J_fly_motor=j_motor, gear_ratio=None if gear_ratio is None else float(gear_ratio),
        delta_simulated=d_sim, delta_without=d0, method=method, cycle=cycle,
        message="; ".join(msgs), stats=FlywheelStats(mean_torque_removed_Nm=imbalance))
