"""Equations of motion, Lagrange's equations of the second kind:

    A(q) q'' + c(q, q') = Q(t, q, q')

in the generalized coordinates q of a model, with the body poses x re-solved
from q at every evaluation (Newton from the last solution, so the assembly
branch is kept by continuity).

Two formulations evaluate the same physics:

``"exact"`` (default)
    With the exact velocity analogs B = dx/dq and the acceleration bias b
    (``xddot = B q'' + b``), and the frame mass matrix M_x(x) and centripetal
    term h(x, xdot) of :mod:`mechdyn.dynamics.inertia` (the body-frame origins
    need not be the centres of mass),

        A = B^T M_x B,   c = B^T (M_x b + h),   Q = B^T F + Q_drive

    (F: applied forces conjugate to x, from ``force_model(model).applied``), plus
    the rotor and gear inertia of the drives on their coordinates.

``"analogs"``
    The source paper's method (METHOD.md section 1): velocity analogs of the
    *partial systems* by central differences with a virtual displacement d
    (0.1 deg by default), A_ij = sum over links of m v*_ci . v*_cj + J_c w*_i w*_j,
    A_ij,k = dA_ij/dq_k by central differences, and the paper's eq. 35 for n
    coordinates, c_i = sum_jk (A_ij,k - 1/2 A_jk,i) q'_j q'_k; generalized forces
    by virtual work over the +-d displacements, Q_k = F . v*_k + Q_drive,k.
    Its error against ``"exact"`` is O(d^2).

The mass matrix is checked positive definite by a Cholesky factorisation; a
singular one raises :class:`~mechdyn.errors.IntegrationError`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import IntegrationError, ModelError
from ..kinematics.analogs import acceleration_bias, default_displacement
from ..kinematics.assembly import assemble, solve_position
from ..kinematics.constraints import extend, full_jacobian
from ..model import Model
from .forces import com_arms, force_model
from .inertia import drive_inertia, frame_mass_matrix, mass_matrix_x

__all__ = ["EquationsOfMotion", "Terms", "FORMULATIONS", "equations_of_motion", "drive_inertia",
           "kinetic_energy", "potential_energy", "mass_matrix"]

#: the formulations of the equations of motion
FORMULATIONS = ("exact", "analogs")
#: compiled path: LU pivot ratio below which a position is checked for singularity by SVD
PIVOT_CHECK = 1e-5


@dataclass(frozen=True)
class Terms:
    """The terms of A q'' + c = Q at one state.

    Attributes
    ----------
    t : float
        Time, s.
    q, qdot, qddot : ndarray, shape (n_q,)
    x, xdot : ndarray, shape (n_x,)
        Body poses and their rates.
    B : ndarray, shape (n_x, n_q)
        Velocity analogs of the body frames, dx/dq.
    A : ndarray, shape (n_q, n_q)
        Generalized mass matrix (kg m^2 for angles, kg for travels, mixed kg m).
    c : ndarray, shape (n_q,)
        Velocity-dependent (Coriolis and centripetal) terms, N m or N.
    Q : ndarray, shape (n_q,)
        Generalized forces, N m or N (drives included).
    Q_drive : ndarray, shape (n_q,)
        The drives' part of Q.
    power_nc : float
        Power of the non-conservative forces (everything but gravity and spring
        stiffness), W.
    """

    t: float
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    B: np.ndarray
    A: np.ndarray
    c: np.ndarray
    Q: np.ndarray
    Q_drive: np.ndarray
    power_nc: float


def mass_matrix(model: Model, x, B) -> np.ndarray:
    """Generalized mass matrix A = B^T M_x B (M_x the frame mass matrix of
    :mod:`mechdyn.dynamics.inertia`), shape (..., n_q, n_q)."""
    B = np.asarray(B, float)
    return np.swapaxes(B, -1, -2) @ frame_mass_matrix(model, x) @ B


def kinetic_energy(model: Model, x, xdot) -> np.ndarray:
    """T = 1/2 sum (m v_c^2 + J_c omega^2), J, shape (...)."""
    xdot = np.asarray(xdot, float)
    arm = com_arms(model, x)
    w = xdot[..., 2::3]
    vx = xdot[..., 0::3] - w * arm[..., 1]
    vy = xdot[..., 1::3] + w * arm[..., 0]
    return 0.5 * np.sum(model.mass * (vx * vx + vy * vy) + model.inertia * w * w, axis=-1)


def potential_energy(model: Model, x) -> np.ndarray:
    """Potential energy of gravity and springs, J, shape (...) (batched over poses)."""
    return force_model(model).potential_energy(x)


class EquationsOfMotion:
    """A(q) q'' + c(q, q') = Q(t, q, q') of a model, evaluated on demand.

    Parameters
    ----------
    model : Model
    formulation : {"exact", "analogs"}
        See the module docstring.
    d : float or array_like, shape (n_q,), optional
        Virtual displacement of the ``"analogs"`` formulation (rad for angles, m
        for travels); default 0.1 deg for angles.
    mode : iterable of str, optional
        Engaged locks (default: the model's initial mode).
    x0 : array_like, shape (n_x,), optional
        A solved pose to start the Newton continuation from (default: the
        assembled sketch).
    backend : {"auto", "numpy", "numba"}
        ``"auto"`` uses the compiled kernel of :mod:`mechdyn.dynamics.compiled`
        when numba is installed and every load is supported there (exact
        formulation only); ``"numba"`` insists on it.

    Attributes
    ----------
    evaluations : int
        Number of evaluations of the equations so far.
    x : ndarray, shape (n_x,)
        The last solved pose (start of the next Newton solve).
    """

    def __init__(self, model: Model, formulation: str = "exact", *, d=None, mode=None,
                 x0=None, backend: str = "auto"):
        if formulation not in FORMULATIONS:
            raise ModelError(f"unknown formulation {formulation!r}; valid formulations: "
                             + ", ".join(repr(f) for f in FORMULATIONS))
        if backend not in ("auto", "numpy", "numba"):
            raise ModelError(f"unknown backend {backend!r}; valid: 'auto', 'numpy', 'numba'")
        self.model = model
        self.formulation = formulation
        self.layout = model.layout(mode)
        self.forces = force_model(model)
        self.extra_inertia = drive_inertia(model)
        if d is None:
            self.d = default_displacement(model)
        else:
            dd = np.broadcast_to(np.asarray(d, float), (model.n_q,)).copy()
            if not np.all(np.isfinite(dd)) or np.any(dd <= 0):
                raise ModelError(f"virtual displacement d must be > 0, got {d!r}")
            self.d = dd
        if x0 is None:
            x0 = getattr(model, "x0", None)
            if x0 is None:
                x0 = assemble(model, layout=self.layout)
        self.x = np.array(x0, dtype=float)
        self._q_last = None
        self._B_last = None
        self.evaluations = 0
        self.kernel = None
        self.backend = "numpy"
        self.backend_note = ""
        if formulation == "exact" and backend in ("auto", "numba"):
            from .compiled import compile_kernel

            self.kernel, note = compile_kernel(model, self.layout)
            self.backend_note = note
            if self.kernel is not None:
                self.backend = "numba"
                self.kernel.reset(self.x)
            elif backend == "numba":
                raise ModelError(f"the compiled (numba) backend is not available: {note}")
        elif backend == "numba":
            raise ModelError("the compiled (numba) backend supports formulation 'exact' only")

    # ------------------------------------------------------------------ positions
    def reset(self, x) -> None:
        """Restart the Newton continuation from the pose ``x`` (n_x,)."""
        self.x = np.array(x, dtype=float)
        self._q_last = None
        self._B_last = None
        if self.kernel is not None:
            self.kernel.reset(self.x)

    def positions(self, q, t: float | None = None, *, check_singular: bool = False) -> np.ndarray:
        """Body poses x (n_x,) at coordinates ``q``, by Newton from the last solution.

        Raises
        ------
        AssemblyError, SingularPositionError
            (the latter only with ``check_singular``).
        """
        q = np.asarray(q, dtype=float)
        if self.kernel is not None:
            x = self.kernel.positions(q)
            if x is not None:
                # the LU pivots are a cheap indicator; confirm a near-singular one by SVD
                if check_singular and self.kernel.pivot_ratio < PIVOT_CHECK:
                    x = solve_position(self.model, q, x, layout=self.layout, t=t,
                                       check_singular=True)
                self.x = x
                return x
            guess = self.kernel.x.copy()
        else:
            guess = self.x
            if self._q_last is not None and self._B_last is not None:
                guess = self.x + self._B_last @ (q - self._q_last)
        x = solve_position(self.model, q, guess, layout=self.layout, t=t,
                           check_singular=check_singular)
        self.x = x
        self._q_last = q.copy()
        self._B_last = None
        if self.kernel is not None:
            self.kernel.reset(x)
        return x.copy()

    # ------------------------------------------------------------------ evaluation
    def rhs(self, t: float, q, qdot):
        """q'' and the non-conservative power at (t, q, q'): ``(qddot (n_q,), p (1,))``.

        This is the right-hand side handed to the integrators.
        """
        if self.kernel is not None:
            out = self.kernel.rhs(t, q, qdot)
            if out is not None:
                return out
            self._kernel_failure(t, q, self.kernel.status)
        self.evaluations += 1
        tm = self._terms(t, np.asarray(q, float), np.asarray(qdot, float))
        return tm.qddot, np.array([tm.power_nc])

    def first_order_function(self):
        """``fun(t, y) -> y'`` for y = (q, q', w) with w' = P_nc, calling the compiled
        kernel directly; None without the compiled backend."""
        if self.kernel is None:
            return None
        n = self.model.n_q

        def on_failure(t, y):
            qdd, p = self.rhs(t, y[:n], y[n:2 * n])
            return np.concatenate([y[n:2 * n], qdd, p])

        return self.kernel.first_order_function(on_failure)

    @property
    def total_evaluations(self) -> int:
        """Evaluations through :meth:`rhs` plus those of the compiled kernel called directly."""
        return self.evaluations + (self.kernel.evaluations if self.kernel is not None else 0)

    def qddot(self, t: float, q, qdot) -> np.ndarray:
        """Generalized accelerations q'' (n_q,) at (t, q, q')."""
        return self.rhs(t, q, qdot)[0]

    __call__ = qddot

    def terms(self, t: float, q, qdot) -> Terms:
        """All terms of the equations at one state (NumPy path, for inspection)."""
        self.evaluations += 1
        if self.kernel is not None:
            self.x = self.kernel.x.copy()
        return self._terms(t, np.asarray(q, float), np.asarray(qdot, float))

    def _kernel_failure(self, t, q, status):
        """The kernel reported a failure: redo the evaluation on the NumPy path, which
        raises the error with its diagnosis (joint residuals, mass matrix)."""
        self.x = self.kernel.x.copy()
        self._q_last = None
        x = solve_position(self.model, np.asarray(q, float), self.x, layout=self.layout, t=t,
                           check_singular=False)
        self.x = x
        self.kernel.reset(x)

    def _terms(self, t, q, qdot) -> Terms:
        if self.formulation == "exact":
            return self._exact(t, q, qdot)
        return self._analogs(t, q, qdot)

    def _solve_mass(self, A, rhs, t, q):
        try:
            L = np.linalg.cholesky(A)
        except np.linalg.LinAlgError:
            ev = np.linalg.eigvalsh(0.5 * (A + A.T))
            k = int(np.argmin(ev))
            vec = np.linalg.eigh(0.5 * (A + A.T))[1][:, k]
            names = [n for n, v in zip(self.model.coordinate_names, vec, strict=True)
                     if abs(v) > 0.1]
            raise IntegrationError(
                f"the generalized mass matrix is singular or not positive definite "
                f"(smallest eigenvalue {ev[k]:.3g}); coordinate(s) {', '.join(names)} have "
                f"no inertia", t=t, q=q) from None
        y = np.linalg.solve(L, rhs)
        return np.linalg.solve(L.T, y)

    def _power(self, F, Qd, x, xdot, qdot) -> float:
        return self.forces.nonconservative_power(None, x, xdot, None, qdot, applied=(F, Qd))

    def _exact(self, t, q, qdot) -> Terms:
        model, lay = self.model, self.layout
        x = self.positions(q, t)
        J = full_jacobian(model, x, lay)
        rhs = np.zeros((J.shape[0], model.n_q))
        rhs[lay.n_rows:, :] = np.eye(model.n_q)
        B = np.linalg.solve(J, rhs) if J.shape[0] == J.shape[1] else np.linalg.pinv(J) @ rhs
        self._B_last = B
        b = acceleration_bias(model, x, B @ qdot, lay, J=J)
        return self._lagrange(t, q, qdot, x, B, b)

    def _lagrange(self, t, q, qdot, x, B, b) -> Terms:
        """The terms at a pose x (n_x,) with its velocity analogs B (n_x, n_q) and
        acceleration bias b (n_x,): A = B^T M_x B, c = B^T (M_x b + h), Q = B^T F + Q_drive
        and q'' = A^-1 (Q - c)."""
        model = self.model
        xdot = B @ qdot
        M, h = mass_matrix_x(model, x, xdot)
        A = B.T @ M @ B + np.diag(self.extra_inertia)
        c = B.T @ (M @ b + h)
        F, Qd = self.forces.applied(t, x, xdot, q, qdot)
        Q = B.T @ F + Qd
        qdd = self._solve_mass(A, Q - c, t, q)
        return Terms(t, q, qdot, qdd, x, xdot, B, A, c, Q, Qd,
                     self._power(F, Qd, x, xdot, qdot))

    def _analogs(self, t, q, qdot) -> Terms:
        model, lay = self.model, self.layout
        n = model.n_q
        x = self.positions(q, t)
        d = self.d
        E = np.diag(d)
        pm = np.concatenate([E, -E])  # (2n, n): +d e_k then -d e_k
        q1 = q + pm
        x1 = solve_position(model, q1, x, layout=lay, t=t, check_singular=False)
        q2 = q1[:, None, :] + pm[None, :, :]  # (2n, 2n, n)
        x2 = solve_position(model, q2, x1[:, None, :], layout=lay, t=t, check_singular=False)

        def analog_mass(xs):
            """A from the poses of the partial systems xs (..., 2n, n_x)."""
            rc = extend(model, xs)[..., :-1, :2] + com_arms(model, xs)  # (..., 2n, nb, 2)
            th = xs[..., 2::3]
            vc = (rc[..., :n, :, :] - rc[..., n:, :, :]) / (2 * d[:, None, None])  # (..,n,nb,2)
            w = (th[..., :n, :] - th[..., n:, :]) / (2 * d[:, None])  # (..., n, nb)
            A = np.einsum("...ibk,...jbk,b->...ij", vc, vc, model.mass)
            A += np.einsum("...ib,...jb,b->...ij", w, w, model.inertia)
            return A

        A = analog_mass(x1) + np.diag(self.extra_inertia)
        A1 = analog_mass(x2)  # (2n, n, n): A at q + d e_k and q - d e_k
        dA = (A1[:n] - A1[n:]) / (2 * d[:, None, None])  # dA[k, i, j] = A_ij,k
        Aijk = np.transpose(dA, (1, 2, 0))  # [i, j, k]
        Ajki = dA  # [i, j, k] -> A_jk,i = dA[i, j, k]
        c = np.einsum("ijk,j,k->i", Aijk - 0.5 * Ajki, qdot, qdot)
        B = ((x1[:n] - x1[n:]) / (2 * d[:, None])).T  # (n_x, n) frame analogs
        xdot = B @ qdot
        F, Qd = self.forces.applied(t, x, xdot, q, qdot)
        Q = B.T @ F + Qd
        qdd = self._solve_mass(A, Q - c, t, q)
        return Terms(t, q, qdot, qdd, x, xdot, B, A, c, Q, Qd,
                     self._power(F, Qd, x, xdot, qdot))

    # ------------------------------------------------------------------ energy
    def energy(self, t: float, q, qdot) -> dict:
        """Kinetic and potential energy (J) and the non-conservative power (W) at one state."""
        tm = self.terms(t, q, qdot)
        T = 0.5 * float(qdot @ tm.A @ qdot)
        return {"kinetic": T, "potential": float(potential_energy(self.model, tm.x)),
                "power_nc": tm.power_nc}


def equations_of_motion(model_or_mechanism, formulation: str = "exact", **kwargs
                        ) -> EquationsOfMotion:
    """:class:`EquationsOfMotion` of a model (a mechanism is compiled first)."""
    model = model_or_mechanism
    if not isinstance(model, Model):
        model = model.compile()
    return EquationsOfMotion(model, formulation, **kwargs)
