"""Kinematics and dynamics of one *mode* of a variable-structure mechanism.

A mode is the set of active switchable constraints (``State.mode``; see
:mod:`mechdyn.model.switchable`).  Its constraint rows are ONE
:class:`~mechdyn.model.rows.Rows`, :attr:`ModeSystem.rowset`: the model's joint
rows (``Model.joint_rows``) followed by one row per active switchable element
(:meth:`SwitchedModel.rows`, three for a weld lock), all evaluated by
:mod:`mechdyn.kernels.rows_numpy` with their exact Jacobian and acceleration
term.  The independent coordinates q_I (:attr:`ModeSystem.coords`) are a subset
of the declared coordinates, chosen by the largest pivots of the declared
coordinates' Jacobian restricted to the mode's null space (coordinates that
became dependent are dropped); :attr:`ModeSystem.independent_rows` are a
maximal independent subset of the rows at the pose the mode was entered.

Dynamics in a mode (reduced, exact), with xddot = B qddot_I + b and the
x-space mass matrix M(x) of bodies whose frames need not sit at their centres
of mass (h(x, xdot) the centripetal terms of the offset centres of mass):

    M (B qddot_I + b) + h = F + Phi_x^T lambda + (friction of sliding contacts)

n_x equations for qddot_I and the multipliers lambda of every row: the
accelerations and all constraint forces (joint reactions, lock forces and
torques, contact forces) come out of one solve.  Redundant rows (a weld over a
pin, statically indeterminate contacts) get the multipliers of least weighted
norm, the weights being the contact compliances (the limit of the compliance-
regularized problem of the cyclic-automata document).  The reactions of joints
and locks follow from the multipliers in :mod:`mechdyn.dynamics.reactions`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..errors import AssemblyError, IntegrationError, LockupError
from ..friction.forward import JointFriction
from ..friction.law import friction_joints
from ..kernels import rows_numpy as RN
from ..kernels.inertia import reduced_force, reduced_mass
from ..kinematics.assembly import (
    column_scale,
    newton,
    position_tol,
    scaled_by_columns,
    singular_report,
)
from ..model.inertia import mass_matrix_x
from ..model.state import Mode
from ..model.workspace import Workspace
from .mode_rows import ModeRows, held_key

if TYPE_CHECKING:
    from ..model.switchable import SwitchedModel

__all__ = ["ModeSystem", "ModeEval", "fmt_mode", "solve_mass", "held_key",
           "independent_row_indices",
           "mode_system"]


def fmt_mode(mode) -> str:
    """A mode for messages: ``{a, b}``."""
    return "{" + ", ".join(sorted(mode)) + "}" if mode else "{} (no switchable constraint)"


# ============================================================================ the mode system
@dataclass
class ModeEval:
    """Everything computed at one state of a mode.

    Attributes
    ----------
    x, xdot, xddot : ndarray, shape (n_x,)
    q, qdot, qddot : ndarray, shape (n_q,)
        All declared coordinates (dependent ones measured on the pose).
    lam : ndarray, shape (n_rows,)
        Multipliers of the rows of :attr:`ModeSystem.rowset` (N for rows in m,
        N m for rows in rad), in the convention M xddot + h = F + Phi_x^T lam.
    F : ndarray, shape (n_x,)
        Applied forces on the poses, drives included.
    F_conservative : ndarray, shape (n_x,) or None
        Forces of gravity and spring stiffness alone at the pose, when they
        came out of the same evaluation of the loads (None otherwise).
    F_friction : ndarray, shape (n_x,) or None
        The friction of the sliding joints on the poses (included in ``F``), or None
        for a model without friction in its joints.
    """

    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    lam: np.ndarray
    F: np.ndarray = field(repr=False, default=None)
    F_conservative: np.ndarray | None = field(repr=False, default=None)
    F_friction: np.ndarray | None = field(repr=False, default=None)


class ModeSystem(ModeRows):
    """The constraint rows, independent coordinates and dynamics of one mode.

    Parameters
    ----------
    sm : SwitchedModel
    mode : frozenset of str
    targets : dict
        Held values of the engaged locks and sticking contacts (see
        :meth:`SwitchedModel.capture_target`).
    x : ndarray, shape (n_x,)
        The pose at which rows and coordinates are chosen.
    prefer : sequence of str
        Declared coordinates to keep independent if possible (the previous set).
    avoid : sequence of str
        Declared coordinates to drop first (``frees`` of the locks just engaged).
    workspace : Workspace, optional
        The run's per-run caches (last pose, predictor), restarted at ``x``; default a
        new one.

    Attributes
    ----------
    rows : list of Row
        The switchable rows of the mode.
    layout : ConstraintLayout
        Their bookkeeping with the joint rows (:class:`~mechdyn.model.ConstraintLayout`).
    rowset : Rows
        Every row of the mode: the joint rows (``n_base`` of them), then ``rows``.
    independent_rows : ndarray of int
        Indices into ``rowset`` of a maximal independent set of rows.
    coords : ndarray of int
        Indices of the independent declared coordinates (n_i of them).

    Raises
    ------
    LockupError
        The mode leaves no freedom that the declared coordinates can describe.
    """

    def __init__(self, sm: SwitchedModel, mode, targets: dict, x, *, prefer=(), avoid=(),
                 workspace: Workspace | None = None):
        self.ws = Workspace() if workspace is None else workspace
        super().__init__(sm, mode, targets, self.ws)
        model, lay = self.model, self.layout
        self._slip = lay.friction if len(lay.slip_rows) else None
        self.x_ref = np.array(x, float)
        # the rows and coordinates chosen at a pose: a pure function of (mode, held values,
        # pose) and (prefer, avoid), kept for the instant (an event builds the same mode at
        # the same pose several times: impact, complementarity, the new segment) in the
        # run's workspace (those of the last pose only)
        held = held_key(self.targets)
        at = _at_pose(self.ws, self.x_ref)
        kept = at.get((self.mode, held)) if held is not None else None
        if kept is None:
            Rs = scaled_by_columns(model, self.row_jacobian(self.x_ref), self.rowset.is_angle)
            rows_i = independent_row_indices(Rs)
            kept = {"rows": rows_i, "GN": self._coordinates_on_null_space(Rs[rows_i])}
            if held is not None:
                at[self.mode, held] = kept
        self.independent_rows = kept["rows"].copy()
        self.dof = model.n_x - len(self.independent_rows)
        choice = (tuple(prefer), tuple(avoid))
        if choice not in kept:
            kept[choice] = self._choose_coordinates(kept["GN"], prefer, avoid)
        self.coords = kept[choice].copy()
        self.coord_names = tuple(model.coordinate_names[k] for k in self.coords)
        self.n_i = len(self.coords)
        # every row and every coordinate, evaluated at once; the position problem
        # [independent rows; g_I - q_I] is the subset _sel of them
        self._all = lay.position_rows
        self._sel = np.concatenate([self.independent_rows, self.n_rows + self.coords])
        self._eye_i = np.zeros((model.n_x, self.n_i))
        self._eye_i[len(self.independent_rows):, :] = np.eye(self.n_i)
        self._rs = 1.0 / column_scale(model)
        self.ws.reset(self.x_ref)
        #: the friction of the joints in this mode (None for a model without it)
        self.friction = JointFriction(self) if friction_joints(model) else None

    def _coordinates_on_null_space(self, Ri) -> np.ndarray | None:
        """G N (n_q, dof): G the scaled coordinate Jacobian, N the null space of the scaled
        independent rows ``Ri`` (None without freedom)."""
        model = self.model
        if model.n_x == Ri.shape[0]:
            return None
        Gs = scaled_by_columns(model, self._coord_jac(self.x_ref), model.coord_is_angle)
        N = np.linalg.svd(Ri)[2][Ri.shape[0]:].T if Ri.shape[0] else np.eye(model.n_x)
        return Gs @ N

    def _choose_coordinates(self, GN, prefer, avoid) -> np.ndarray:
        """Pivots of G N (:meth:`_coordinates_on_null_space`), weighted by ``prefer`` and
        ``avoid``."""
        model = self.model
        if self.dof == 0:
            return np.zeros(0, int)
        names = model.coordinate_names
        w = np.ones(model.n_q)
        for k, n in enumerate(names):
            if n in avoid:
                w[k] = 1e-6
            elif prefer and n not in prefer:
                w[k] = 0.5
        import scipy.linalg
        piv = scipy.linalg.qr((GN * w[:, None]).T, pivoting=True)[2]
        chosen = np.sort(piv[:self.dof])
        sv = np.linalg.svd(GN[chosen], compute_uv=False)
        if sv.size < self.dof or sv[-1] < 1e-8 * max(1.0, sv[0]):
            raise LockupError(
                f"mode {fmt_mode(self.mode)} leaves {self.dof} degree(s) of freedom that "
                f"the declared coordinates ({', '.join(names)}) cannot describe")
        return chosen

    def _coord_jac(self, x) -> np.ndarray:
        """Jacobian of all declared coordinates, shape (n_q, n_x)."""
        return RN.jacobian(self.model.coordinate_rows, x)

    def coordinates(self, x) -> np.ndarray:
        """All declared coordinates measured on a pose, shape (n_q,)."""
        return RN.values(self.model.coordinate_rows, x)

    # ------------------------------------------------------------------ positions
    def solve_position(self, qi, x_guess=None, t=None) -> np.ndarray:
        """Pose x (n_x,) at independent coordinates ``qi`` (n_i,), by Newton from ``x_guess``.

        Without ``x_guess`` the start is the last solution moved to ``qi`` along
        its velocity analogs (a first-order predictor), which keeps the branch.

        Raises
        ------
        AssemblyError
            Newton does not converge; the message names the open rows.
        """
        qi = np.asarray(qi, float)
        x = self.ws.predict(qi) if x_guess is None else np.array(x_guess, float)
        n_r = len(self.independent_rows)
        tol = position_tol(self.model)
        x, done = newton(self._all, x, np.concatenate([np.zeros(n_r), qi]), sel=self._sel,
                         tol=tol)
        if not done:
            res = {r: float(v) for r, v in zip(self.row_labels(), self.row_values(x), strict=True)
                   if abs(v) > 1e3 * tol} if np.all(np.isfinite(x)) else {}
            raise AssemblyError(
                f"the mechanism cannot be assembled in mode {fmt_mode(self.mode)}",
                t=t, q=qi, residuals=res)
        p = RN.Parts(self._all, x)
        v = RN.values(self._all, x, p)
        self.ws.x, self.ws.parts = x, (x, p, v)
        return x

    def velocity_analogs(self, x):
        """B (n_x, n_i) with xdot = B qdot_I, and the square Jacobian [rows_I; g_I] at x."""
        J = RN.jacobian(self._all, x)[self._sel]
        B = np.linalg.solve(J, self._eye_i) if J.size else np.zeros((self.model.n_x, 0))
        return B, J

    def rcond(self, x) -> float:
        """sigma_min / sigma_max of the mode's square position Jacobian [rows_I; g_I] at
        x, lengths and angles on one scale (1 where the mode has no freedom)."""
        return self.singularity(x)["rcond"]

    def singularity(self, x, jacobian=None) -> dict:
        """Singular-value report of the scaled position Jacobian [rows_I; g_I] at x:
        ``rcond`` (sigma_min / sigma_max), ``coordinates`` (those whose equations carry
        the left null vector: they lose control) and ``joints`` (the elements whose rows
        become dependent).  ``jacobian``: the Jacobian of all the mode's position rows at
        x (n_rows + n_q, n_x), where the caller has it, else evaluated here."""
        J = (RN.jacobian(self._all, x) if jacobian is None else jacobian)[self._sel]
        rows = [self.rowset.elements[r] for r in self.independent_rows]
        Js = scaled_by_columns(self.model, J, self._all.is_angle[self._sel])
        return singular_report(Js, rows, self.coord_names)

    def state(self, qi, qdoti, x_guess=None, t=None):
        """(x, xdot, B) at independent coordinates and rates."""
        x = self.solve_position(qi, x_guess, t)
        B, _ = self.velocity_analogs(x)
        self.ws.B, self.ws.qi = B, np.array(qi, float)
        return x, B @ np.asarray(qdoti, float), B

    def independent(self, x, xdot):
        """(q_I, qdot_I) measured on a pose and its rates."""
        G = self._coord_jac(x)[self.coords]
        return self.coordinates(x)[self.coords], G @ xdot

    # ------------------------------------------------------------------ dynamics
    def _kinematics(self, x, xdot=None, B=None, qdoti=None, b=None):
        """(R, G, B, b, xdot, quad_g, q) at a pose: the row and coordinate Jacobians,
        the velocity analogs, xddot = B qddot_I + b (unless given), the coordinates'
        quadratic terms and values."""
        n_rows, allr = self.n_rows, self._all
        at = self.ws.parts
        if at is not None and at[0] is x:  # the pose just solved: its parts and values
            p, v = at[1], at[2]
        else:
            p = RN.Parts(allr, x)
            v = RN.values(allr, x, p)
        RG = RN.jacobian(allr, x, p)
        R, G = RG[:n_rows], RG[n_rows:]
        J = RG[self._sel]
        if B is None:
            B = np.linalg.solve(J, self._eye_i) if J.size else np.zeros((self.model.n_x, 0))
        if xdot is None:
            xdot = B @ np.asarray(qdoti, float)
            self.ws.B = B
        quad = RN.quad(allr, x, xdot, p)
        if b is None:
            b = np.linalg.solve(J, -quad[self._sel]) if J.size else np.zeros(0)
        return R, G, B, b, xdot, quad[n_rows:], v[n_rows:]

    def evaluate(self, t, qi, qdoti, x_guess=None) -> ModeEval:
        """Accelerations and every multiplier at a state of the mode."""
        x = self.solve_position(qi, x_guess, t)
        ev = self.evaluate_x(t, x, None, qdoti=qdoti)
        self.ws.qi = np.array(qi, float)
        return ev

    def evaluate_x(self, t, x, xdot, B=None, *, qdoti=None, b=None) -> ModeEval:
        """As :meth:`evaluate`, from a consistent pose and velocity (or, with
        ``xdot`` None, the independent rates ``qdoti``).

        With the analogs ``B`` and the bias ``b`` of a branch chart (at a bifurcation,
        where the rows lose rank), the accelerations come from the reduced equations
        B^T M B qddot_I = B^T (F - h - M b) and the multipliers of least norm."""
        R, G, B, b_, xdot, quad_g, q = self._kinematics(x, xdot, B, qdoti, b)
        qdot = G @ xdot
        F, Qd, Fc = self.sm.fm.applied_and_conservative(t, x, xdot, q, qdot)
        F = F + G.T @ Qd
        M, h = self.sm.with_drive_inertia(*mass_matrix_x(self.model, x, xdot), G, quad_g)
        rhs = F - h - M @ b_
        Ff = None if self.friction is None else np.zeros_like(F)
        if b is not None:
            qddi = np.linalg.solve(reduced_mass(M, B), reduced_force(B, rhs))
            lam = np.linalg.lstsq(R.T, M @ (B @ qddi) - rhs, rcond=None)[0]
        else:
            Reff = R
            if self._slip is not None:
                Reff = R.copy()
                Reff[self.layout.slip_rows] += RN.jacobian(self._slip, x)
            if self.friction is not None and self.friction.sliding:
                sol, Ff = self.friction.solve(self._linear_solve(M, B, Reff, self._rs),
                                              self.n_i, rhs, x, xdot, t=t, q=q)
                qddi, lam = sol[:self.n_i], sol[self.n_i:]
                F = F + Ff
            else:
                qddi, lam = self._solve_motion(M, B, Reff, rhs, self._rs)
        xddot = B @ qddi + b_
        qddot = G @ xddot + quad_g
        return ModeEval(x, xdot, xddot, q, qdot, qddot, lam, F, Fc, Ff)

    def _solve_motion(self, M, B, Reff, rhs, rs):
        """Solve [M B, -Reff^T] [qddot_i; lam] = rhs (rows scaled by ``rs``) for the
        independent accelerations and the multipliers; redundant sets by least squares."""
        sol = self._linear_solve(M, B, Reff, rs)(rhs)
        return sol[:self.n_i], sol[self.n_i:]

    def _linear_solve(self, M, B, Reff, rs):
        """``lin(rhs) -> [qddot_i; lam]`` of [M B, -Reff^T] (rows scaled by ``rs``),
        rhs (n_x,) or (n_x, k); redundant sets by least squares."""
        Ks = np.concatenate([M @ B, -Reff.T], axis=1) * rs[:, None]

        square = Ks.shape[0] == Ks.shape[1]

        def lin(rhs):
            r = rhs * (rs if rhs.ndim == 1 else rs[:, None])
            if square:
                try:
                    return np.linalg.solve(Ks, r)
                except np.linalg.LinAlgError:
                    pass
            if self.n_i:  # a coordinate without inertia is named, not solved around
                solve_mass(self.coord_names, reduced_mass(M, B), np.zeros(self.n_i), None, None)
            return self._redundant_solve(Ks, r)

        return lin

    def _redundant_solve(self, Ks, rhs):
        """Least-squares solution of a rank-deficient [M B, -Phi^T] system whose
        multipliers are not unique: among all solutions, the one minimizing
        sum c_k lambda_k^2 over the compliant contact rows (c_k their compliances;
        1 for rigid unilateral rows, ~0 for the rigid joints and locks); among those
        of the joints and locks, the least sum (lambda_k / s_k)^2, s_k the model's
        length scale for an angle row (a moment) and 1 for a force: the minimum norm
        of :func:`mechdyn.kinetostatics`, so that both report the same reactions."""
        sol0, *_ = np.linalg.lstsq(Ks, rhs, rcond=None)
        u, s, vt = np.linalg.svd(Ks)
        rank = int(np.sum(s > 1e-11 * (s[0] if s.size else 1.0)))
        N = vt[rank:].T
        if N.shape[1] == 0:
            return sol0
        w = np.full(Ks.shape[1], 1e-9)
        w[self.n_i:] /= np.where(self.rowset.is_angle, self.model.length_scale, 1.0) ** 2
        comp = np.array([r.compliance for r in self.rows], float)
        cpos = comp[comp > 0]
        cref = float(np.mean(cpos)) if cpos.size else 1.0
        for k, r in enumerate(self.rows):
            if r.unilateral:
                w[self.n_i + self.n_base + k] = comp[k] / cref if comp[k] > 0 else 1.0
        NW = N.T * w
        z = -np.linalg.lstsq(NW @ N, NW @ sol0, rcond=None)[0]
        return sol0 + N @ z

    def terms(self, t, x, xdot):
        """Reduced dynamics at a consistent state: A qddot_I = f (no friction terms).

        Returns
        -------
        dict with B (n_x, n_i), b (n_x,) [xddot = B qddot_I + b], A (n_i, n_i)
        generalized mass matrix, f (n_i,) = B^T (F - h - M b), M (n_x, n_x).
        """
        _, G, B, b, xdot, quad_g, q = self._kinematics(x, xdot)
        F, Qd = self.sm.fm.applied(t, x, xdot, q, G @ xdot)
        F = F + G.T @ Qd
        M, h = self.sm.with_drive_inertia(*mass_matrix_x(self.model, x, xdot), G, quad_g)
        return dict(B=B, b=b, A=reduced_mass(M, B), f=reduced_force(B, F, h, M, b), M=M, F=F, h=h)


def solve_mass(names, A, rhs, t, q) -> np.ndarray:
    """A^-1 rhs by Cholesky; a mass matrix that is not positive definite names the
    coordinates without inertia.

    Raises
    ------
    IntegrationError
    """
    try:
        import scipy.linalg
        return scipy.linalg.cho_solve(scipy.linalg.cho_factor(A), rhs)
    except np.linalg.LinAlgError:
        ev, vec = np.linalg.eigh(0.5 * (A + A.T))
        names = [n for n, v in zip(names, vec[:, 0], strict=True) if abs(v) > 0.1]
        raise IntegrationError(
            f"the generalized mass matrix is singular or not positive definite "
            f"(smallest eigenvalue {ev[0]:.3g}); coordinate(s) {', '.join(names)} have "
            f"no inertia", t=t, q=q) from None


def _at_pose(ws: Workspace, x) -> dict:
    """What the run (``ws``) keeps for the pose ``x``: the entries of the last pose only."""
    pose = np.asarray(x, float).tobytes()
    if ws.at_pose is None or ws.at_pose[0] != pose:
        ws.at_pose = (pose, {})
    return ws.at_pose[1]


def mode_system(sm: SwitchedModel, mode, targets: dict, x, *, prefer=(), avoid=(),
                workspace: Workspace | None = None) -> ModeSystem:
    """The :class:`ModeSystem` of ``mode`` at the pose ``x``: the one the run built there
    with the same held values and choices if it did (a switching instant builds the same
    mode at its pose for the impact, the complementarity and the next segment), restarted
    at ``x`` as a new one would be; else a new one (then kept for this pose).  Without a
    ``workspace``, or with friction in the joints (whose mode systems carry the pairs'
    states), always a new one.

    Parameters
    ----------
    sm : SwitchedModel
    mode : frozenset of str
    targets : dict
        Held values of the engaged locks and sticking contacts; part of the key (equal
        values by :func:`held_key`; a held value that is not numbers: never kept).
    x : ndarray, shape (n_x,)
        The pose (m, rad); part of the key, byte for byte (only the last pose is kept).
    prefer, avoid : sequence of str
        As in :class:`ModeSystem`; part of the key.
    workspace : Workspace, optional
        The run's workspace, where the mode systems of the pose are kept
        (:attr:`~mechdyn.model.workspace.Workspace.at_pose`); None: a new mode system
        with a workspace of its own.

    Returns
    -------
    ModeSystem
        Its workspace restarted at ``x`` (``workspace.reset``).

    Raises
    ------
    LockupError
        As :class:`ModeSystem` (a new one only).

    Examples
    --------
    >>> import mechdyn
    >>> from mechdyn.model.switchable import switched_model
    >>> from mechdyn.model.workspace import Workspace
    >>> sm = switched_model(mechdyn.examples.load("press_cycle").compile())
    >>> ws, x = Workspace(), sm.model.x_sketch
    >>> a = mode_system(sm, frozenset(), {}, x, workspace=ws)
    >>> a is mode_system(sm, frozenset(), {}, x, workspace=ws), a.coord_names
    (True, ('phi', 'psi', 'p'))
    """
    held = held_key(targets)
    if workspace is None or held is None or friction_joints(sm.model):
        return ModeSystem(sm, mode, targets, x, prefer=prefer, avoid=avoid,
                          workspace=workspace)
    key = ("system", Mode(mode), held, tuple(prefer), tuple(avoid))
    at = _at_pose(workspace, x)
    ms = at.get(key)
    if ms is None or ms.x_ref.tobytes() != workspace.at_pose[0]:
        ms = ModeSystem(sm, mode, targets, x, prefer=prefer, avoid=avoid, workspace=workspace)
        _at_pose(workspace, x)[key] = ms
    else:
        ms.ws.reset(ms.x_ref)
    return ms


def independent_row_indices(Rs, tol=1e-9) -> np.ndarray:
    """Indices of a maximal set of linearly independent rows, earlier rows first."""
    keep = []
    basis = np.zeros((0, Rs.shape[1]))
    scale = max(np.max(np.abs(Rs)) if Rs.size else 1.0, 1e-300)
    if 0 < Rs.shape[0] <= Rs.shape[1]:
        # every row at least sigma_min away from the span of the others: all are kept by
        # the test below (with a margin of 10 for its rounding), found with one SVD
        A = Rs / scale
        floor = max(tol * float(np.max(np.linalg.norm(A, axis=1))), 1e-12)
        if np.linalg.svd(A, compute_uv=False)[-1] > 10.0 * floor:
            return np.arange(Rs.shape[0])
    for k in range(Rs.shape[0]):
        r = Rs[k] / scale
        if basis.shape[0]:
            r = r - basis.T @ (basis @ r)
            r = r - basis.T @ (basis @ r)
        nr = np.linalg.norm(r)
        if nr > tol * max(np.linalg.norm(Rs[k] / scale), 1e-300) and nr > 1e-12:
            basis = np.vstack([basis, r / nr])
            keep.append(k)
    return np.array(keep, int)
