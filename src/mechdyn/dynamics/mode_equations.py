"""The equations of motion of one mode, as the integrators see them.

Lagrange II in the independent coordinates q_I of the mode (a subset of the
declared coordinates, chosen by :class:`~mechdyn.dynamics.mode_system.ModeSystem`):
A(q) q_I'' = Q - c, with the rows of every active element (joints, engaged
locks, closed stops and contacts, sticking contacts) and the rotor and gear
inertia of the drives reduced to their coordinates.  A fixed-structure run is a
run in one mode.  The right-hand side runs on the compiled kernel
(:mod:`mechdyn.dynamics.compiled`) whenever the mode allows (numba installed,
every load compiled, no sliding friction); otherwise, and to diagnose a failure,
on the NumPy evaluation of the mode (:meth:`ModeSystem.evaluate`), which also
gives every multiplier.  Friction in the joints (:mod:`mechdyn.friction.forward`)
runs on the NumPy path: its force depends on the multipliers, and each evaluation
solves the coupled system by Newton's method on them (the compiled kernel, whose
signature frictionless runs keep, has no friction).

Two formulations evaluate the same physics: ``"exact"`` (the exact velocity
analogs, every mode) and ``"analogs"``, the source paper's finite-difference
analogs of the partial systems (:meth:`ModeEquations.analogs_terms`; modes in
which every declared coordinate is independent, on the NumPy path).

Through bifurcation positions (a parallelogram lying flat: the rows lose rank
but the motion stays determined) a one-coordinate mode of the joints alone takes
its pose, analogs and bias from a branch chart
(:mod:`mechdyn.kinematics.branch_chart`) inside a zone |q - q*| < 0.15 rad
(0.15 length scale for a travel) around the crossing: the limit of the branch
from both sides, reached by continuation (the branch kept is the one the motion
is on).  Outside the zones the compiled kernel keeps its speed; inside, the
chart's error (about 1e-13 in the acceleration of the parallelogram) replaces the
eps/d^3 blow-up of the equations evaluated at a distance d from the crossing.
At a *dead* position (a fold) no chart exists and the run stops there.  Why not
an x-space formulation (augmented Lagrangian, or the KKT system with
minimum-norm multipliers)?  At the crossing the constraint force is the limit of
Phi_x^T lambda with lambda ~ 1/d and need not lie in the range of Phi_x^T at the
singular pose, so a minimum-norm solve there gives a wrong acceleration.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..errors import AssemblyError, ModelError, SingularPositionError
from ..friction.law import friction_joints
from ..kernels.inertia import analog_mass, reduced_force
from ..kinematics.analogs import default_displacement
from ..kinematics.assembly import SINGULAR_RCOND, solve_position
from ..kinematics.branch_chart import BranchChart, ChartBook, PathProblem
from ..model.constraints import extend
from ..model.forces import com_arms
from .compiled import compile_mode_kernel
from .dead_position import _dependent, _where
from .mode_system import ModeEval, solve_mass

__all__ = ["ModeEquations", "BACKENDS", "FORMULATIONS", "PIVOT_CHECK", "STAGE_FAILURES"]

#: valid values of ``backend``
BACKENDS = ("auto", "numpy", "numba")
#: the formulations of the equations of motion
FORMULATIONS = ("exact", "analogs")
#: compiled path: LU pivot ratio below which a position is checked for singularity by SVD
PIVOT_CHECK = 1e-5
#: failed position solves at the stages of a step that reject it (the step shrinks) before
#: the failure ends the run (diagnosed from the last accepted state): a trial step far too
#: long may leave the assembly region that the motion itself stays in
STAGE_FAILURES = 8


class ModeEquations:
    """q_I'' = f(t, q_I, q_I') of one mode, with the power of the non-conservative forces.

    Parameters
    ----------
    sm : SwitchedModel
    ms : ModeSystem
        The mode (rows, independent coordinates, targets of the locks).
    backend : {"auto", "numpy", "numba"}
        ``"auto"`` uses the compiled kernel when it can; ``"numba"`` insists on it.
    formulation : {"exact", "analogs"}
        See the module docstring.
    d : float or array_like, shape (n_q,), optional
        Virtual displacement of ``"analogs"`` (rad for angles, m for travels;
        default 0.1 deg, and 0.1 deg x length scale for travels).

    Attributes
    ----------
    kernel : CompiledKernel or None
    backend : str
        ``"numba"`` or ``"numpy"``, what this mode runs on.
    note : str
        Why the compiled path is not used, or ``""``.
    book : ChartBook or None
        The branch charts of a one-coordinate mode of the joints alone with a closed
        loop (exact formulation), else None (an open chain has no bifurcation).
    watching : bool
        Whether evaluations look out for bifurcations (off while a caller samples
        dense output, so that output times do not change the run).

    Raises
    ------
    ModelError
        An unknown backend or formulation, ``backend="numba"`` where the compiled path
        cannot run, ``"analogs"`` in a mode with dependent coordinates, a bad ``d``.
    """

    def __init__(self, sm, ms, backend: str = "auto", formulation: str = "exact", d=None):
        if backend not in BACKENDS:
            raise ModelError(f"unknown backend {backend!r}; valid: "
                             + ", ".join(repr(b) for b in BACKENDS))
        if formulation not in FORMULATIONS:
            raise ModelError(f"unknown formulation {formulation!r}; valid formulations: "
                             + ", ".join(repr(f) for f in FORMULATIONS))
        model = ms.model
        self.sm, self.ms, self.formulation = sm, ms, formulation
        self.kernel, self.note, self.book = None, "", None
        self.watching, self._s_last = True, None
        self._anchor, self._failures, self._rejects = None, 0, 0  # see anchor
        self.d = default_displacement(model)
        if formulation == "analogs":
            if ms.friction is not None:
                raise ModelError(f"joint {friction_joints(model)[0]!r} has friction; formulation "
                                 "'analogs' does not model friction yet (use 'exact')")
            if ms.rows or ms.n_i != model.n_q:
                raise ModelError("formulation 'analogs' needs a mode in which every declared "
                                 "coordinate is independent (no engaged lock, closed stop or "
                                 f"contact); mode {sorted(ms.mode)}")
            if d is not None:
                dd = np.broadcast_to(np.asarray(d, float), (model.n_q,)).copy()
                if not np.all(np.isfinite(dd)) or np.any(dd <= 0):
                    raise ModelError(f"virtual displacement d must be > 0, got {d!r}")
                self.d = dd
            if backend == "numba":
                raise ModelError("the compiled (numba) backend supports formulation "
                                 "'exact' only")
            self.note = "formulation 'analogs' is evaluated on the NumPy path"
        elif backend != "numpy":
            if any(r.slip for r in ms.rows):
                self.note = "sliding friction is evaluated on the NumPy path"
            elif ms.friction is not None:
                self.note = ("the friction of joint(s) " + ", ".join(
                    repr(j) for j in friction_joints(model)) + " is evaluated on the NumPy "
                    "path (Newton on the multipliers per evaluation)")
            else:
                self.kernel, self.note = compile_mode_kernel(
                    model, sm.fm, ms.rowset.take(ms.independent_rows), ms.coords,
                    kept=ms.ws.kernels)
            if self.kernel is None and backend == "numba":
                raise ModelError(f"the compiled (numba) backend is not available: {self.note}")
        if self.kernel is not None:
            self.kernel.reset(ms.x_ref)
        loops = len(model.rev.names) + len(model.pri.names) > model.n_bodies  # not a tree
        if (formulation == "exact" and loops and not ms.rows and model.n_q == ms.n_i == 1
                and ms.friction is None
                and len(ms.independent_rows) == ms.n_rows == model.n_x - 1):
            lay = model.layout(sorted(ms.mode.locks))
            self.book = ChartBook(PathProblem(model, lay, [0], [0.0], 0))
        self.backend = "numba" if self.kernel is not None else "numpy"
        # the kernel's multipliers are those of the independent rows: all of them unless
        # the mode has redundant rows (their share is chosen on the NumPy path)
        self._full = len(ms.independent_rows) == ms.n_rows
        self._in_order = self._full and np.array_equal(ms.independent_rows,
                                                       np.arange(ms.n_rows))

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, t: float, qi, qdi) -> ModeEval:
        """Everything at a state of the mode (:class:`ModeEval`: poses, rates,
        accelerations of every declared coordinate, every multiplier): from a branch
        chart in a bifurcation zone, from the compiled kernel when the mode has no
        redundant rows, else from the NumPy evaluation."""
        ms = self.ms
        ch = self.chart_at(qi)
        if ch is not None:
            return self._chart_eval(ch, t, qi, qdi)
        if self.formulation == "analogs":
            ev = ms.evaluate(t, qi, qdi)
            ev.qddot = self.analogs_terms(t, qi, qdi, ev.x)["qddot"]
            return ev
        if self.kernel is not None and self._full:
            k = self.kernel.evaluation(t, qi, qdi)
            if k is not None:
                if self._in_order:  # the kernel's rows are the mode's, in order
                    return ModeEval(*k)
                lam = np.zeros(ms.n_rows)
                lam[ms.independent_rows] = k[6]
                return ModeEval(*k[:6], lam, k[7])
        return self._numpy_evaluate(t, qi, qdi)

    def _numpy_evaluate(self, t: float, qi, qdi) -> ModeEval:
        """The NumPy evaluation, its Newton solve started from the kernel's last pose."""
        k = self.kernel
        return self.ms.evaluate(t, qi, qdi, x_guess=None if k is None else k.x.copy())

    def _power(self, ev) -> float:
        """Power of the non-conservative forces at an evaluation (all applied forces but
        gravity and spring stiffness, and the sliding friction of slipping contacts), W."""
        Fc = ev.F_conservative
        p = float((ev.F - (self.sm.fm.conservative(ev.x) if Fc is None else Fc)) @ ev.xdot)
        ms = self.ms
        return p + float(sum(-r.mu * r.slip * ev.lam[ms.n_base + k] * r.tangent.rate(ev.x, ev.xdot)
                             for k, r in enumerate(ms.rows) if r.slip))

    def _powers(self, ev) -> np.ndarray:
        """[P_nc] or, with friction in the joints, [P_nc, P_f]: P_f = -F_f . xdot >= 0
        the power the joints' friction dissipates (its work is recorded on its own)."""
        if ev.F_friction is None:
            return np.array([self._power(ev)])
        return np.array([self._power(ev), -float(ev.F_friction @ ev.xdot)])

    def numpy_rhs(self, t: float, qi, qdi):
        """(q_I'', array([P_nc]) or array([P_nc, P_f]) with friction in the joints) on
        the NumPy path; raises the diagnosed error of a failure (assembly, lock-up)."""
        if self.formulation == "analogs":
            tm = self.analogs_terms(t, qi, qdi)
            return tm["qddot"], np.array([tm["power_nc"]])
        ev = self._numpy_evaluate(t, qi, qdi)
        return ev.qddot[self.ms.coords], self._powers(ev)

    def rhs(self, t: float, qi, qdi):
        """(q_I'' (n_i,), array([P_nc]) or, with friction in the joints,
        array([P_nc, P_f])) at (t, q_I, q_I')."""
        n = self.ms.n_i
        w0 = [0.0, 0.0] if self.ms.friction is not None else [0.0]
        out = self._first_order(t, np.concatenate([qi, qdi, w0]))
        return out[n:2 * n], out[2 * n:]

    def first_order_function(self):
        """``fun(t, y) -> y'`` for y = (q_I, q_I', w) on the compiled kernel (the branch
        charts inside bifurcation zones), or None without the compiled kernel."""
        return None if self.kernel is None else self._first_order

    @cached_property
    def _first_order(self):
        """y' = (q_I', q_I'', P_nc) on the compiled kernel, else (and where the kernel
        fails) on the NumPy path; from a branch chart inside a bifurcation zone."""
        n = self.ms.n_i

        def numpy_path(t, y):
            qdd, p = self.numpy_rhs(t, y[:n], y[n:2 * n])
            return np.concatenate([y[n:2 * n], qdd, p])

        base = numpy_path if self.kernel is None else self.kernel.first_order_function(
            numpy_path)
        book = self.book
        if book is None:
            return self._anchored(base)

        def fun(t, y):
            if book.charts:
                ch = self._zone(y[:1])
                if ch is not None:
                    return self._chart_first_order(ch, t, y)
            out = base(t, y)
            s = float(y[0])
            if not book.due(s):
                self._s_last = s
                return out
            ch = self._watch(s)
            return out if ch is None else self._chart_first_order(ch, t, y)

        return self._anchored(fun)

    def _anchored(self, fun):
        """``fun`` with its position solves started from the anchor, when one is set; a
        failed position solve there rejects the trial step (NaN rates) up to
        :data:`STAGE_FAILURES` times after the last accepted step, then raises."""

        def anchored(t, y):
            if self._anchor is None:
                return fun(t, y)
            if not np.all(np.isfinite(y)):  # a stage after a failed one: rejected anyway
                return np.full(y.size, np.nan)
            self._to_anchor()
            try:
                return fun(t, y)
            except AssemblyError:
                self._failures += 1
                if self._failures > self._rejects:
                    raise
                self._to_anchor()
                return np.full(y.size, np.nan)

        return anchored

    def anchor(self, reject_failures: bool = True) -> None:
        """Start the position solves of the next step's stages from the pose solved last
        (the end of the step just accepted), every stage of every attempt of the step;
        with ``reject_failures``, a failed solve returns NaN rates (an integrator that
        rejects such a step shrinks it) up to :data:`STAGE_FAILURES` times, else raises.

        The Newton solves otherwise go on from the last pose solved, and the stages of a
        rejected trial step may have left the assembly branch (a step ten times too long
        through the press's open chain); its retries, and the step accepted at last,
        would then go on on the other branch.  The compiled loop does the same for its
        steps (:mod:`mechdyn.kernels.dop853_numba`); set by
        :func:`mechdyn.integrate.segment.run_segment` after every accepted step.
        """
        ws, k = self.ms.ws, self.kernel
        self._failures, self._rejects = 0, STAGE_FAILURES if reject_failures else 0
        self._anchor = (None if k is None else k.snapshot(), ws.x, ws.B, ws.qi, ws.parts)

    def _to_anchor(self) -> None:
        saved, *kept = self._anchor
        ws = self.ms.ws
        ws.x, ws.B, ws.qi, ws.parts = kept
        if saved is not None:
            self.kernel.restore(saved)

    # ------------------------------------------------------------------ branch charts
    def chart_at(self, qi) -> BranchChart | None:
        """The chart whose zone holds the coordinates q_I, else None."""
        if self.book is None or not self.book.charts:
            return None
        return self.book.zone_chart(float(np.asarray(qi, float).reshape(-1)[0]))

    def report(self) -> list[dict]:
        """The bifurcation positions met (see :meth:`ChartBook.report`)."""
        return [] if self.book is None else self.book.report()

    def _zone(self, qi) -> BranchChart | None:
        """The chart whose zone holds q_I; outside the zones, prepare the direct Newton
        solve: start it from the chart's pose in a chart window, or from the window's
        edge when the step jumps over a chart."""
        s = float(np.asarray(qi, float).reshape(-1)[0])
        book = self.book
        ch = book.zone_chart(s)
        if ch is not None:
            return ch
        win = book.window_chart(s)
        if win is None and self._s_last is not None:
            win = book.crossed(self._s_last, s)
            if win is not None:
                s = win.centre + np.sign(s - win.centre) * win.window
        if win is not None:
            self.reset(win.evaluate(s)[0])
        return None

    def _watch(self, s: float) -> BranchChart | None:
        """After a direct solve at s: build a chart if a singular position is within
        reach; returns it if its zone holds s."""
        self._s_last = s
        if not self.watching or not self.book.due(s):
            return None
        k = self.kernel
        x = k.x.copy() if k is not None and not k.status else self.ms.ws.x
        ch = self.book.watch(s, x)
        return ch if ch is not None and ch.in_zone(s) else None

    def reset(self, x) -> None:
        """Restart the Newton continuation from the pose ``x`` (n_x,)."""
        self.ms.ws.reset(x)
        if self.kernel is not None:
            self.kernel.reset(x)

    def _chart_eval(self, ch: BranchChart, t, qi, qdi) -> ModeEval:
        qd = np.asarray(qdi, float).reshape(-1)
        x, xs, xss = ch.evaluate(float(np.asarray(qi, float).reshape(-1)[0]))
        self.reset(x)
        return self.ms.evaluate_x(t, x, xs * qd[0], xs[:, None], b=xss * qd[0] ** 2)

    def _chart_first_order(self, ch, t, y):
        ev = self._chart_eval(ch, t, y[:1], y[1:2])
        return np.concatenate([y[1:2], ev.qddot[self.ms.coords], [self._power(ev)]])

    # ------------------------------------------------------------------ checks
    def check_position(self, t: float, x, q) -> None:
        """Stop at a singular position of the mode (dead, toggle or bifurcation position:
        the mode's coordinates lose control), with t, q and the coordinates named.

        A cheap test first (the pivots of the compiled kernel's last factorization),
        confirmed by the singular values of the scaled position Jacobian.  Inside a
        bifurcation zone the branch chart carries the run on.

        Raises
        ------
        SingularPositionError
            sigma_min / sigma_max of [rows_I; g_I] below ``SINGULAR_RCOND``.
        """
        if self.kernel is not None and self.kernel.pivot_ratio >= PIVOT_CHECK:
            return
        if self.chart_at(np.asarray(q)[self.ms.coords]) is not None:
            return
        rep = self.ms.singularity(x)
        if rep["rcond"] >= SINGULAR_RCOND:
            return
        raise SingularPositionError(
            f"singular position in mode {sorted(self.ms.mode) or '(none)'} at t = {t:.9g} s, "
            f"{_where(self.ms, q)}: sigma_min/sigma_max of the position Jacobian "
            f"{rep['rcond']:.2e}; the {_dependent(rep)}", t=t, q=q)

    # ------------------------------------------------------------------ analogs
    def analogs_terms(self, t: float, q, qdot, x=None) -> dict:
        """The terms of A q'' + c = Q by the method of reference [1] (docs/references.md)
        at a state of the mode: velocity analogs of the *partial systems* by central
        differences with the virtual displacement d, A_ij = sum over links of
        m v*_ci . v*_cj + J_c w*_i w*_j (plus the drives' rotor and gear inertia),
        A_ij,k = dA_ij/dq_k by central differences, the paper's eq. 35 for n
        coordinates, c_i = sum_jk (A_ij,k - 1/2 A_jk,i) q'_j q'_k, and generalized
        forces by virtual work, Q_k = F . v*_k + Q_drive,k.  Its error against the
        exact formulation is O(d^2).

        Returns
        -------
        dict with x, xdot, B (n_x, n) frame analogs, A (n, n), c, Q, Q_drive, qddot
        (n,) and power_nc (W).
        """
        ms, d = self.ms, self.d
        model = ms.model
        q, qdot = np.asarray(q, float), np.asarray(qdot, float)
        if x is None:
            x = ms.solve_position(q, t=t)
        lay = model.layout(sorted(ms.mode.locks))
        n = model.n_q
        E = np.diag(d)
        pm = np.concatenate([E, -E])  # (2n, n): +d e_k then -d e_k
        q1 = q + pm
        x1 = solve_position(model, q1, x, layout=lay, t=t, check_singular=False)
        q2 = q1[:, None, :] + pm[None, :, :]  # (2n, 2n, n)
        x2 = solve_position(model, q2, x1[:, None, :], layout=lay, t=t, check_singular=False)

        def partial_mass(xs):
            """A from the poses of the partial systems xs (..., 2n, n_x)."""
            rc = extend(model, xs)[..., :-1, :2] + com_arms(model, xs)  # (..., 2n, nb, 2)
            th = xs[..., 2::3]
            vc = (rc[..., :n, :, :] - rc[..., n:, :, :]) / (2 * d[:, None, None])
            w = (th[..., :n, :] - th[..., n:, :]) / (2 * d[:, None])  # (..., n, nb)
            return analog_mass(vc, w, model.mass, model.inertia)

        A = partial_mass(x1) + np.diag(self.sm.drive_inertia)
        A1 = partial_mass(x2)  # (2n, n, n): A at q + d e_k and q - d e_k
        dA = (A1[:n] - A1[n:]) / (2 * d[:, None, None])  # dA[k, i, j] = A_ij,k
        c = np.einsum("ijk,j,k->i", np.transpose(dA, (1, 2, 0)) - 0.5 * dA, qdot, qdot)
        B = ((x1[:n] - x1[n:]) / (2 * d[:, None])).T  # (n_x, n) frame analogs
        xdot = B @ qdot
        fm = self.sm.fm
        F, Qd = fm.applied(t, x, xdot, q, qdot)
        Q = reduced_force(B, F) + Qd
        qdd = solve_mass(model.coordinate_names, A, Q - c, t, q)
        p = fm.nonconservative_power(None, x, xdot, None, qdot, applied=(F, Qd))
        return dict(x=x, xdot=xdot, B=B, A=A, c=c, Q=Q, Q_drive=Qd, qddot=qdd, power_nc=p)

