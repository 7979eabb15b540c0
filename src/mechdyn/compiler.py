"""The compiler: a :class:`~mechdyn.mechanism.Mechanism` becomes a validated, constant Model.

:func:`compile_mechanism` is the one place a model is built and validated, in order:

1. the problems of the description that need no solving
   (:meth:`Mechanism.problems <mechdyn.mechanism.Mechanism.problems>`);
2. the index layout, parameter arrays and constraint rows (:class:`mechdyn.model.Model`);
3. the sketch assembled and the coordinates and constraints checked by rank
   (:func:`check_rank`, with :mod:`mechdyn.kinematics.assembly`);
4. the loads, drives and every switchable element -- locks, stops, contacts and
   switches with their targets, variables and guards (:func:`check_loads`, by building
   :func:`mechdyn.model.forces.force_model` and
   :func:`mechdyn.model.switchable.switched_model` once),

so that an analysis never discovers a bad name.  The module sits above the analyses
it borrows from; :meth:`Mechanism.compile <mechdyn.mechanism.Mechanism.compile>` and
:func:`mechdyn.model.as_model` hand a mechanism to it.

:func:`warmup` compiles the Numba kernels ahead of time (``mechdyn warmup``): they are
compiled once per machine into the user's cache folder
(:func:`mechdyn.kernels.cache_dir`), otherwise on their first use.
"""

from __future__ import annotations

import numpy as np

from .errors import MechdynError, ModelError
from .kinematics.assembly import assemble, rank_report
from .model import Model
from .model.constraints import coordinates
from .model.forces import force_model
from .model.switchable import switched_model

__all__ = ["compile_mechanism", "check_rank", "check_loads", "warmup"]

_GRUEBLER = "degrees of freedom"


def compile_mechanism(mechanism) -> Model:
    """Validate a mechanism and build its constant :class:`~mechdyn.model.Model`.

    Parameters
    ----------
    mechanism : Mechanism

    Returns
    -------
    Model
        With ``x0`` (the assembled sketch, shape (n_x,)) and ``redundant`` (the
        joints whose rows are redundant) set by :func:`check_rank`.

    Raises
    ------
    ModelError
        Listing every problem found (names, masses, DOF count, rank, loads, drives,
        switchable elements).

    Examples
    --------
    >>> from mechdyn import Mechanism
    >>> m = Mechanism("pendulum")
    >>> _ = m.add_body("bar", mass=2.0, inertia=0.05, com=(0.5, 0.0))
    >>> _ = m.add_revolute("O", "ground", "bar")
    >>> _ = m.add_coordinate("theta", kind="angle", body="bar")
    >>> compile_mechanism(m).n_q
    1
    """
    probs = mechanism.problems()
    # A Gruebler mismatch may be a redundant constraint set: decided by rank below.
    gruebler = [p for p in probs if p.startswith(_GRUEBLER)]
    if probs and not (mechanism.bodies and mechanism.coordinates and gruebler
                      and len(gruebler) == len(probs)):
        raise ModelError(probs)
    model = Model(mechanism)
    check_rank(model, gruebler_message=probs[-1] if probs else None)
    return check_loads(model).freeze()


def check_rank(model: Model, gruebler_message: str | None = None) -> None:
    """Assemble the sketch and check the coordinates and constraints by rank.

    Sets ``model.x0`` (the assembled sketch), ``model.q_sketch`` (its coordinates) and
    ``model.redundant``.

    Raises
    ------
    ModelError
        If the coordinates are not independent, if the DOF count does not match
        and the constraints are not merely redundant, or if the sketch cannot be
        assembled.
    """
    try:
        x0 = assemble(model)
    except (MechdynError, np.linalg.LinAlgError, ValueError) as exc:  # AssemblyError says where
        probs = [f"the initial sketch cannot be assembled: {exc}"]
        if gruebler_message is not None:
            probs.insert(0, gruebler_message)
        raise ModelError(probs) from exc
    model.x0 = x0
    model.q_sketch = coordinates(model, x0)
    rep = rank_report(model, x0)
    model.redundant = rep["redundant_joints"]
    problems = []
    if rep["dependent_coordinates"]:
        problems.append(
            "coordinates are not independent at the sketch position: "
            + ", ".join(repr(c) for c in rep["dependent_coordinates"])
            + " can be expressed by the others (choose coordinates that each move a "
            "different part of the mechanism)")
    dof_rank = model.n_x - rep["rank_phi"]
    if dof_rank != model.n_q:
        problems.append(
            f"the mechanism has {dof_rank} degree(s) of freedom at the sketch position "
            f"(rank of the constraint Jacobian {rep['rank_phi']}), but {model.n_q} "
            f"coordinate(s) are declared")
    elif gruebler_message is not None and not model.redundant:
        problems.append(gruebler_message)
    if problems:
        raise ModelError(problems)


def check_loads(model: Model) -> Model:
    """Validate the loads, drives and every switchable element (locks, stops, contacts,
    switches with their targets, variables and guards) of a compiled model.

    Returns
    -------
    Model
        ``model`` itself, with ``forces`` (the loads and drives resolved) and
        ``switchable`` (the switchable elements) set.

    Raises
    ------
    ModelError
        Listing every problem found.
    """
    probs: list[str] = []
    for attr, build in (("forces", force_model), ("switchable", switched_model)):
        try:
            setattr(model, attr, build(model))
        except ModelError as exc:
            probs.extend(p for p in exc.problems if p not in probs)
    if probs:
        raise ModelError(probs)
    return model


def warmup() -> dict[str, float]:
    """Compile every Numba kernel now (or load it from the disk cache), so that the first
    analysis of each kind does not wait for it.

    The kernels are generic over their arrays: compiling them on a small pendulum of
    their own compiles them for every model.  They are kept in
    :func:`mechdyn.kernels.cache_dir`, once per machine; a later call, or a later
    process, only loads them.  Each group compiled for the first time on the machine is
    announced on stderr with its time, as on first use.

    Returns
    -------
    dict of str to float
        Wall time (s) of each group of kernels and ``"total"``: ``"dynamics"`` (the
        evaluations of the equations of motion of :func:`mechdyn.simulate`),
        ``"integration loop"`` (its compiled DOP853 loop, :mod:`mechdyn.kernels.dop853_numba`),
        ``"fixed-step loop"`` (RK4 and Wilson's method, compiled), ``"first-order f"``
        (the f SciPy's methods call), ``"turning check"`` (the position Jacobian of the
        turning-point check; :data:`mechdyn.dynamics.compiled.GROUPS`; a run compiles only
        the groups it uses), ``"kinematic sweep"`` (the position problem of
        :func:`mechdyn.sweep`) and
        ``"batched study"`` (the kinetostatics of many variants at once of
        :mod:`mechdyn.study`, :mod:`mechdyn.kernels.rows_variants`).  A group already
        compiled in this process counts 0 s.  Empty when Numba is not installed (the
        analyses then run on NumPy, nothing to compile).

    Examples
    --------
    >>> times = warmup()
    >>> sorted(times) in ([], ["batched study", "dynamics", "first-order f", "fixed-step loop",
    ...                        "integration loop", "kinematic sweep", "total",
    ...                        "turning check"])
    True
    """
    import time

    from .dynamics.compiled import numba_available, warm_up_groups
    from .kernels.rows_numba import compiling
    from .kinematics.continuation import Kernel
    from .mechanism import Mechanism

    if not numba_available():
        return {}
    t0 = time.perf_counter()
    times = warm_up_groups()
    t1 = time.perf_counter()
    mech = Mechanism("warm-up pendulum")
    mech.add_body("bar", mass=1.0, inertia=0.1, com=(0.5, 0.0))
    mech.add_revolute("O", "ground", "bar")
    mech.add_coordinate("theta", kind="angle", body="bar")
    model = compile_mechanism(mech)
    kernel = Kernel(model, model.layout())  # compiles the sweep's drivers on construction
    kernel.gamma(model.x0, np.zeros(model.n_x))
    t2 = time.perf_counter()
    with compiling("numba kernels of the batched study"):
        _warm_up_study(model)
    t3 = time.perf_counter()
    times.update({"kinematic sweep": t2 - t1, "batched study": t3 - t2, "total": t3 - t0})
    return times


def _warm_up_study(model: Model) -> None:
    """Compile (or load) the batched kinetostatics of :mod:`mechdyn.study`
    (:mod:`mechdyn.kernels.rows_variants`) on a one-coordinate ``model``: one variant along
    two positions, with arrays of the types the study passes."""
    from .kernels.rows_variants import inverse_variants, path_variants

    lay = model.layout()
    crd = model.coordinate_rows
    ints = np.ascontiguousarray(np.concatenate([lay.rowset.packed()[0], crd.packed()[0]]))
    flts = np.ascontiguousarray(np.concatenate([lay.rowset.packed()[1], crd.packed()[1]])[None])
    n, n_x, m = len(ints), model.n_x, 2
    Q = np.array([[[0.0], [0.1]]])
    dQ, ddQ = np.ones((m, 1)), np.zeros((m, 1))
    X, Xd, Xdd = (np.empty((1, m, n_x)) for _ in range(3))
    J, LU = np.empty((1, m, n, n_x)), np.empty((1, m, n, n_x))
    piv, rc = np.empty((1, m, n), dtype=np.int64), np.empty((1, m))
    ok, fail = np.ones(1, dtype=bool), np.empty(1, dtype=np.int64)
    path_variants(np.ascontiguousarray(model.x0[None]), Q, dQ, ddQ, np.arange(m), model.n_bodies,
                  ints, flts, lay.n_rows, np.full(1, 1e-12), 12, 1e7, 1e-9, X, Xd, Xdd, J, LU,
                  piv, rc, ok, fail)
    # the study passes its right-hand sides C-contiguous (one specialization)
    inverse_variants(LU, piv, np.zeros((1, m, n)), lay.n_rows, np.empty((1, m, n)))
