"""Reactions of joints and locks from multipliers (the one reporter, for forward runs,
impacts and kinetostatics: :func:`joint_reaction`), and the batched kinetostatic solve
for the multipliers and driving torques, the frame loads and the redundancy check (the
equation and sign conventions of :mod:`mechdyn.kinetostatics.inverse`).
"""

from __future__ import annotations

import warnings as _warnings

import numpy as np

from ..contact.compliance import share_by_compliance
from ..errors import ModelError, Status
from ..friction.forward import friction_set, joint_states
from ..friction.kinetostatic import friction_solve, locking_note
from ..friction.law import friction_joints
from ..kernels import rows_numpy
from ..kernels.planar import cross, perp, rotate
from ..kinematics.assembly import SINGULAR_RCOND, column_scale, redundant_rows
from ..model import ConstraintLayout, Model
from ..model.constraints import coordinates_jacobian, extend
from ..model.forces import applied_forces
from ..model.inertia import inertia_forces

__all__ = ["KinetostaticsWarning", "joint_reaction", "reaction_frame", "element_forces",
           "element_width", "frame_forces", "touches_ground", "ground_rows", "batched_inverse"]

#: relative singular value below which constraint equations count as dependent
REDUNDANT_RCOND = 1e-9
#: rcond of the scaled inverse-dynamics matrix below which a position is reported
#: as close to singular (a warning; the solve is still exact)
NEAR_SINGULAR_RCOND = 1e-6


class KinetostaticsWarning(UserWarning):
    """Redundant constraints or singular positions in a kinetostatic analysis."""


def _redundancy(model, lay, x) -> tuple[int, list[str], list[str]]:
    """Number of dependent joint equations at poses x (n, n_x), the joints involved and
    row labels."""
    if x.shape[0] > 64:  # redundancy is structural: a sample of the positions suffices
        x = x[np.unique(np.linspace(0, x.shape[0] - 1, 64).astype(int))]
    rank, rows = redundant_rows(rows_numpy.jacobian(lay.rowset, x) * column_scale(model),
                                 REDUNDANT_RCOND)
    n_red = lay.n_rows - rank
    if n_red == 0:
        return 0, [], []
    joints = sorted({str(lay.row_joint[i]) for i in rows})
    labels = [lay.rowset.labels[i] if i >= lay.n_base else
              "{} ({})".format(*lay.rowset.labels[i].rsplit(".", 1)) for i in rows]
    return n_red, joints, labels


def reaction_frame(model: Model, name: str) -> tuple[str, int, int, np.ndarray]:
    """(kind, parent index, child index, reaction point in the child frame (2,) m) of a
    joint or weld lock.

    The reaction point is the joint point: the child's point of a revolute or
    prismatic joint; for a weld lock the child frame origin, which the lock holds
    at the offset c in the parent frame.
    """
    for kind, tab in (("revolute", model.rev), ("prismatic", model.pri)):
        if name in tab.names:
            k = tab.names.index(name)
            return kind, int(tab.i[k]), int(tab.j[k]), np.asarray(tab.sj[k], float)
    k = model.lock.names.index(name)
    return "lock", int(model.lock.i[k]), int(model.lock.j[k]), np.zeros(2)


def joint_reaction(model: Model, name: str, x, gen, friction=None):
    """The reaction of a joint or weld lock: the force and the moment on the CHILD body
    from the PARENT, at the joint point (:func:`reaction_frame`), in the ground frame.

    Parameters
    ----------
    model : Model
    name : str
        A revolute or prismatic joint or a weld lock.
    x : array_like, shape (..., n_x)
        Poses.
    gen : array_like, shape (..., n_x)
        The constraint force of the element's rows on the poses, Phi_e,x^T lambda_e
        (force, N, and moment about each body frame origin, N m), in the
        convention M xddot + h = F + Phi_x^T lambda.
    friction : array_like, shape (..., n_x), optional
        The generalized force of the pair's friction on the poses (the law's,
        :meth:`~mechdyn.friction.law.FrictionSet.by_pair`, or the constraint force
        of the stick row of a sticking pair): part of the reaction.  A revolute joint's
        moment is then the moment of this friction about the pin (the friction moment
        on the child).

    Returns
    -------
    force : ndarray, shape (..., 2)
        N.
    moment : ndarray, shape (...)
        N m about the joint point; zero for a revolute joint without ``friction``.
        With the ground as
        the child, minus the parent's share (action and reaction).
    point : ndarray, shape (..., 2)
        The joint point in the ground frame, m.
    """
    kind, i, j, sj = reaction_frame(model, name)
    X = extend(model, np.asarray(x, float))
    gen = np.asarray(gen, float)
    P = X[..., j, :2] + rotate(X[..., j, 2], sj)
    b, sgn = (j, 1.0) if j < model.n_bodies else (i, -1.0)

    def about_p(g):
        return g[..., 3 * b + 2] - cross(P - X[..., b, :2], g[..., 3 * b:3 * b + 2])

    if friction is not None:
        friction = np.asarray(friction, float)
        gen = gen + friction
    m = about_p(gen)
    if kind == "revolute":  # the pin transmits no moment but its friction's
        m = about_p(friction) if friction is not None else np.zeros(np.shape(m))
    return sgn * gen[..., 3 * b:3 * b + 2], sgn * m, P


def element_forces(ms, x, lam, friction=None, R=None) -> dict:
    """The force of every element of a mode from its multipliers (batched over poses).

    Parameters
    ----------
    ms : ModeSystem
    x : ndarray, shape (..., n_x)
    lam : ndarray, shape (..., n_rows)
        Multipliers of ``ms.rowset`` (forward convention); impulses give impulses.
    friction : dict, optional
        {joint: generalized force (..., n_x) of its friction} of the slipping pairs
        (:meth:`~mechdyn.friction.forward.JointFriction.by_pair`).
    R : ndarray, shape (..., n_rows, n_x), optional
        The row Jacobian at ``x`` (``ms.row_jacobian(x)``) when the caller has it.

    Returns
    -------
    dict
        Joints and weld locks: their reaction (:func:`joint_reaction`), (..., 2)
        (Fx, Fy) N for a revolute joint, (..., 3) (Fx, Fy, M) N, N, N m for a
        prismatic joint, a weld or a revolute joint with friction (M its friction
        moment on the child); coordinate locks, stops and contacts: the
        multiplier of their (first) row, shape (...) (the normal force of a stop or
        contact, N or N m, the torque or force of a coordinate lock along its variable).
        The friction of a pair is part of its reaction: the law's (``friction``) or,
        when it sticks, the force of its stick row (:mod:`~mechdyn.friction.forward`),
        as :func:`mechdyn.kinetostatics` reports it.
    """
    model = ms.model
    R = ms.row_jacobian(x) if R is None else R
    lam = np.asarray(lam, float)
    fj = friction_joints(model)
    friction = friction or {}
    out: dict = {}
    for el, idx in ms.element_rows.items():
        if el not in model.mechanism.joints:
            out[el] = lam[..., idx[0]] if lam.ndim > 1 else float(lam[idx[0]])
            continue
        is_stick = np.array([k >= ms.n_base and ms.rows[k - ms.n_base].kind == "stick"
                             for k in idx], bool)
        base, stick = idx[~is_stick], idx[is_stick]
        gen = np.einsum("...rx,...r->...x", R[..., base, :], lam[..., base])
        fric = friction.get(el)
        if stick.size:  # a sticking pair: its stick row holds it by friction
            held = np.einsum("...rx,...r->...x", R[..., stick, :], lam[..., stick])
            fric = held if fric is None else fric + held
        if el in fj and fric is None:
            fric = np.zeros_like(gen)
        f, m, _ = joint_reaction(model, el, x, gen, fric)
        out[el] = f if model.joint_kind(el) == "revolute" and el not in fj else np.concatenate(
            [f, np.asarray(m)[..., None]], axis=-1)
    return out


def element_width(model, name: str) -> int:
    """The width of a joint's or weld's force in :func:`element_forces`: 2 (Fx, Fy) for a
    revolute joint without friction, else 3 (Fx, Fy, M)."""
    return 2 if model.joint_kind(name) == "revolute" and name not in friction_joints(model) \
        else 3


def frame_forces(ms, x, lam, point=None, R=None) -> dict:
    """Forces (Fx, Fy), shape (..., 2), N, that the mechanism exerts on the frame through
    each element of a mode attached to the ground (joint, lock, stop or contact);
    key ``"total"`` sums them (batched over poses ``x`` (..., n_x) and multipliers
    ``lam`` (..., n_rows)).  With ``point`` (2,) m, each entry is (Fx, Fy, M), shape
    (..., 3), with the moment M about that point, N m.  ``R``: the row Jacobian at ``x``
    when the caller has it."""
    R = ms.row_jacobian(x) if R is None else R
    lam = np.asarray(lam, float)
    width = 2 if point is None else 3
    p = np.zeros(2) if point is None else np.asarray(point, float)
    shape = lam.shape[:-1] + (width,)
    out: dict = {}
    for el, idx in ms.element_rows.items():
        if el in ms.grounded:
            gen = np.einsum("...rx,...r->...x", R[..., idx, :], lam[..., idx])
            # Newton's third law: the frame gets the opposite of the force on the bodies
            out[el] = net_on_ground(ms.model, x, gen, p)[..., :width].reshape(shape)
    out["total"] = sum(out.values(), np.zeros(shape))
    return out


def touches_ground(rows) -> bool:
    """True if constraint rows act between the frame and a moving body
    (:func:`ground_rows`)."""
    return bool(np.any(ground_rows(rows)))


def ground_rows(rows) -> np.ndarray:
    """Which constraint rows act between the frame and a moving body, shape (n,) bool: a
    point on the ground, an angle of the ground, or an absolute angle."""
    g = rows.nb
    pts = np.any(rows.u != 0.0, axis=1) & ((rows.b1 == g) | (rows.b2 == g))
    ang = ((rows.ka != 0.0) & (rows.a == g)) | ((rows.kb != 0.0) & (rows.bb == g)) | (
        (rows.ka != 0.0) != (rows.kb != 0.0))
    return pts | ang


def net_on_ground(model: Model, x, D, point) -> np.ndarray:
    """What the frame receives from force elements between it and the moving bodies:
    minus the net force and moment about ``point`` (2,) m of their forces on the bodies.

    Parameters
    ----------
    model : Model
    x : ndarray, shape (n, n_x)
        Poses.
    D : ndarray, shape (n, n_x)
        Forces (N) and moments about the body frame origins (N m) of the elements on
        the bodies (elements acting between two moving bodies add nothing).
    point : array_like, shape (2,)

    Returns
    -------
    ndarray, shape (n, 3)
        (Fx, Fy) N and the moment about ``point``, N m.
    """
    Db = D.reshape(-1, model.n_bodies, 3)
    r = np.reshape(x, Db.shape)[..., :2] - point
    m = (Db[..., 2] + cross(r, Db[..., :2])).sum(axis=1)
    return -np.concatenate([Db[..., :2].sum(axis=1), m[:, None]], axis=-1)


def _share_by_compliance(model: Model, lay: ConstraintLayout, red_joints, As, bs, cs, z,
                         ok) -> str:
    """Where every joint of the redundant set has a compliance (a pin's ``compliance``,
    m/N, on its two force rows), replace the minimum-norm solution ``z`` (scaled, (n, m))
    at the samples ``ok`` by the one of least complementary energy
    (:func:`~mechdyn.contact.compliance.share_by_compliance`), in place.  Returns the
    sentence for the warning ('' where the minimum norm stays)."""
    joints = model.mechanism.joints
    given = {j: float(getattr(joints.get(j), "compliance", 0.0) or 0.0) for j in red_joints}
    if not any(c > 0 for c in given.values()):
        return ""
    missing = [j for j, c in given.items() if not c > 0]
    if missing:
        return ("the minimum-norm solution is reported: the compliance of joint(s) "
                + ", ".join(repr(j) for j in missing) + " is not given (every joint of the "
                "redundant set needs one to share the reactions by compliance)")
    w = np.zeros(As.shape[2])
    for j, c in given.items():
        rows = lay.rows[j]
        w[rows] = c * cs[rows] ** 2  # the energy in the scaled unknowns z / cs
    W = np.diag(w)
    failed = 0
    for k in np.flatnonzero(ok):
        try:
            z[k] = share_by_compliance(As[k], bs[k], W)
        except ModelError:
            failed += 1  # the minimum norm stays there
    return ("they are shared by the joints' compliances (" + ", ".join(
        f"{j} {c:.4g} m/N" for j, c in given.items()) + "; least complementary energy, "
        "docs/indeterminacy.md)" + (f", but for {failed} position(s) where that failed "
                                    "(minimum norm there)" if failed else ""))


def batched_inverse(model: Model, lay: ConstraintLayout, didx, t, x, xdot, xddot, q, qdot, *,
             skip, reacting, point, charted=None) -> dict:
    """The batched inverse-dynamics solve and the reaction bookkeeping: the record fields
    it gives (as named in ``Kinetostatics``), ``tau`` (n, n_d), ``status``, ``warnings``
    and ``stats``.  ``charted`` = (mask (n,), x', x''): samples near a bifurcation, where
    one driven coordinate's torque is the virtual work along the branch's tangent x',
    tau = x'^T (I - F) (the reactions do no work along it)."""
    n = t.shape[0]
    L = model.length_scale
    n_d = len(didx)
    warn: list[str] = []
    F, F_ground, Qd_loads = applied_forces(model, t, x, xdot, q, qdot, skip_drives=skip,
                                           reacting_loads=reacting)
    Ix = inertia_forces(model, x, xdot, xddot)
    P = rows_numpy.jacobian(lay.rowset, x)  # (n, rows, n_x)
    if len(lay.slip_rows):  # slipping contacts' rows: R - mu s T_x
        P[:, lay.slip_rows, :] += rows_numpy.jacobian(lay.friction, x)
    G = coordinates_jacobian(model, x)  # (n, n_q, n_x)
    Gd = G[:, didx, :]
    A = np.concatenate([-P, Gd], axis=1).transpose(0, 2, 1)  # (n, n_x, rows + n_d)
    rhs = Ix - F
    # balance units: moment equations / L; moment-like unknowns scaled by L
    rs = 1.0 / column_scale(model)
    cs = np.where(np.concatenate([lay.rowset.is_angle, model.coord_is_angle[didx]]), L, 1.0)
    As = A * rs[:, None] * cs[None, :]
    bs = rhs * rs
    mask = charted[0] if charted is not None else np.zeros(n, dtype=bool)
    n_red, red_joints, red_labels = _redundancy(model, lay, x[~mask] if (~mask).any() else x)
    sv = np.linalg.svd(As, compute_uv=False)
    rank_need = lay.n_rows + n_d - n_red
    smax = sv[:, 0]
    s_need = sv[:, rank_need - 1] if rank_need > 0 else smax
    rcond = s_need / np.where(smax > 0, smax, 1.0)
    singular = rcond < SINGULAR_RCOND
    if n_red == 0 and As.shape[1] == As.shape[2] and not singular.any():
        z = np.linalg.solve(As, bs[..., None])[..., 0]
    else:
        z = (np.linalg.pinv(As, rcond=1e-10) @ bs[..., None])[..., 0]
    shared = ""
    if n_red:  # redundant joints with compliances: shared by them, not by the minimum norm
        shared = _share_by_compliance(model, lay, red_joints, As, bs, cs, z,
                                      ~singular & ~mask)
    # the friction of the pairs: the law's for the slipping ones (in the direction of a
    # switched mode's slip state where their speed is zero), the stick rows' multipliers
    # for those that stick (docs/friction.md)
    fj = friction_joints(model)
    states = joint_states(model, lay.mode)
    fs = friction_set(model, tuple(j for j in fj if states.get(j) != "stick"))
    signs = {j: 1.0 if st == "slip+" else -1.0 for j, st in states.items() if st != "stick"}
    held = {r.element: lay.n_base + k for k, r in enumerate(lay.extra)
            if r.kind == "stick" and r.element in fj}
    Ff, locked = np.zeros_like(F), np.zeros(n, dtype=bool)
    finfo = {"iterations": 0}
    if fs:  # the nonlinear system, by Newton from z
        z, Ff, locked, finfo = friction_solve(fs, {j: lay.rows[j] for j in fs.names},
                                              lay.n_rows, As, bs, rs, cs, x, xdot, z,
                                              signs=signs)
        locked &= ~mask  # bifurcations: the torque is the limit along the branch
        rhs = rhs - Ff
        bs = rhs * rs
    resid = np.abs(np.einsum("nij,nj->ni", As, z) - bs).max(axis=-1)
    singular |= resid > 1e-6 * np.maximum(np.maximum(np.abs(bs).max(axis=-1), 1e-300),
                                          np.abs(As).max(axis=(1, 2)) * np.abs(z).max(axis=-1))
    z = z * cs
    z[locked] = np.nan  # no finite driving torque moves the mechanism there
    lam = z[:, :lay.n_rows]
    tau = z[:, lay.n_rows:]
    if mask.any() and n_d == 1:
        tau[mask, 0] = np.einsum("nx,nx->n", charted[1], rhs[mask])
    singular &= ~locked
    bif = singular & mask
    singular &= ~mask
    status = Status.SUCCESS
    if n_red:
        status = Status.REDUNDANT
        warn.append(f"{n_red} redundant joint equation(s): the equations "
                    + ", ".join(red_labels) + " are linearly dependent, so the reactions of "
                    "joints " + ", ".join(repr(j) for j in red_joints) + " are not unique; "
                    + (shared or "the minimum-norm solution is reported (forces in N, moments "
                       f"in N m divided by the length scale {L:.4g} m)"))
        rf = [j for j in red_joints if j in fs.names]
        if rf:
            warn.append("the friction of joint(s) " + ", ".join(repr(j) for j in rf)
                        + " depends on their reactions, which are not unique: it is computed "
                          "from the minimum-norm reactions")
    for where, what, why in (
            (bif, "bifurcation position(s)", "the mechanism goes on on its branch and the "
             "driving torque there is its limit along the branch, but the joint equations are "
             "dependent: the reactions there are unbounded (least-squares values)"),
            (singular, "singular position(s)", "the driven coordinates do not control the "
             "mechanism there; reactions there are least-squares values")):
        if where.any():
            status, k = Status.SINGULAR_POSITION, int(np.argmax(where))
            warn.append(f"{int(where.sum())} {what} (first at index {k}, t = {t[k]:.6g} s): "
                        + why)
    if locked.any():
        status = Status.SELF_LOCKING
        warn.append(locking_note(model, didx, t, q, locked, finfo))
    near = (rcond < NEAR_SINGULAR_RCOND) & ~singular & ~bif & ~locked
    if near.any():
        k = int(np.argmin(np.where(near, rcond, np.inf)))
        warn.append(f"{int(near.sum())} position(s) close to a singular position (smallest "
                    f"rcond {rcond[k]:.2e} at index {k}, t = {t[k]:.6g} s): reactions and "
                    f"driving torques there are large and sensitive to the geometry")
    for w in warn:
        _warnings.warn(w, KinetostaticsWarning, stacklevel=3)

    # ------------------------------------------------ joint reactions
    X = extend(model, x)
    C = -P * lam[:, :, None]  # row contributions to generalized forces (n, rows, n_x)
    reactions, moments, jframe, jpoints, kinds = {}, {}, {}, {}, {}
    frame_loads: dict[str, np.ndarray] = {}
    lam_f = {j: lay.rows[j] for j in fs.names}
    F_pair = {j: Fp for j, (Fp, _) in fs.by_pair(x, xdot, -lam, lam_f, signs).items()}
    F_pair.update({j: C[:, k, :] for j, k in held.items()})  # a sticking pair's friction
    for name in (n for n in model.joint_names if n in lay.rows):
        kind, i, j, _ = reaction_frame(model, name)
        gen = C[:, lay.rows[name], :].sum(axis=1)
        # the friction of the pair is part of its reaction (a pin's: its moment)
        f, mP, Pt = joint_reaction(model, name, x, gen, F_pair.get(name))
        gen = gen + F_pair.get(name, 0.0)
        reactions[name], moments[name], jpoints[name], kinds[name] = f, mP, Pt, kind
        # prismatic: along and normal to the axis; else along the parent's x and y axes
        u = rotate(X[:, i, 2], model.pri.ui[model.pri.names.index(name)]
                   if kind == "prismatic" else (1.0, 0.0))
        jframe[name] = np.stack([np.sum(f * u, -1), np.sum(f * perp(u), -1)], axis=-1)
        if model.n_bodies in (i, j):  # attached to the ground
            frame_loads[name] = net_on_ground(model, x, gen, point)

    # ------------------------------------------------ switchable elements (modes.py rows)
    el_forces: dict[str, np.ndarray] = {}
    p_el = np.zeros(n)
    for el, idx in lay.elements.items():
        # the multiplier in the forward convention (M xddot = F + R^T lambda_m):
        # the normal force of a stop or contact (>= 0), the torque/force of a
        # coordinate lock on its measure, the tangential force of a sticking contact
        el_forces[el] = -lam[:, idx[0]]
        if idx[0] in held.values():  # a sticking pair's friction: in its joint's loads
            continue
        Del = C[:, idx, :].sum(axis=1)
        p_el += np.einsum("nx,nx->n", Del, xdot)
        frame_loads[el] = net_on_ground(model, x, Del, point)

    # ------------------------------------------------ drives' stator and ground-attached loads
    D = np.einsum("nd,ndx->nx", tau, Gd) + np.einsum("nq,nqx->nx", Qd_loads, G)
    frame_loads["drives"] = net_on_ground(model, x, D, point)
    frame_loads["loads"] = F_ground - np.concatenate(
        [np.zeros((n, 2)), cross(point, F_ground[:, :2])[:, None]], axis=-1)
    tot = sum(frame_loads.values())
    # ------------------------------------------------ power balance (self-check)
    # (p_el: power of the switchable rows, zero but for sliding friction)
    p_out = -np.einsum("nx,nx->n", F, xdot)  # useful: against the applied loads
    p_in = np.einsum("nd,nd->n", tau, qdot[:, didx]) - p_out + p_el
    lost = fs.power_lost(x, xdot, -lam, lam_f, signs)
    losses = {j: lost.get(j, np.zeros(n)) for j in fj}  # none in a sticking pair
    p_in -= sum(losses.values(), np.zeros(n))
    p_kin = np.einsum("nx,nx->n", Ix, xdot)
    p_scale = np.nanmax([np.nanmax(np.abs(p_kin)), np.nanmax(np.abs(p_in)),
                         np.nanmax(np.abs(F * xdot)), 1e-300])
    bal = np.abs(p_in - p_kin)[~locked]
    stats = {"power_balance_rel": float(bal.max() / p_scale) if bal.size else float("nan"),
             "rcond_min": float(np.min(rcond)), "redundant_equations": n_red,
             "redundant_shared_by": ("compliance" if shared.startswith("they are shared")
                                     else "minimum norm") if n_red else None,
             "singular_positions": int(singular.sum()),
             "bifurcation_positions": int(bif.sum()),
             **({"self_locked_positions": int(locked.sum()),
                 "friction_iterations": finfo["iterations"]} if fj else {})}
    return {"reactions": reactions, "moments": moments, "joint_frame": jframe,
            "joint_points": jpoints, "joint_kinds": kinds, "frame_loads": frame_loads,
            "frame_force": tot[:, :2].copy(), "frame_moment": tot[:, 2].copy(),
            "multipliers": lam, "element_forces": el_forces, "redundant_joints": tuple(red_joints),
            "tau": tau, "status": status, "warnings": warn, "stats": stats,
            **({"losses": losses, "power_out": p_out, "locked": locked} if fj else {})}

