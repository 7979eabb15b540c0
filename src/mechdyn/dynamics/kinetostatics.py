"""Kinetostatics (inverse dynamics for a given motion): driving torques, joint
reactions, and the loads the frame and foundation receive.

The generalized coordinates follow a prescribed motion (a constant speed, a law
of time, or a trajectory from forward dynamics).  Driving constraints
``g_d(x) - q_d(t) = 0`` are appended to the joint constraints ``Phi(x) = 0``;
with the body poses ``x`` and their rates known, the Lagrange multipliers follow
from one linear solve per position (batched over all positions at once)::

    -Phi_x^T lambda + g_d,x^T tau = I(x, xdot, xddot) - F(t, x, xdot)

* ``I`` are the inertia forces conjugate to the body-frame poses: for each body
  ``m a_c`` and ``J_c alpha + a x m a_c`` (``a``: the centre of mass relative to
  the frame origin) -- i.e. ``M_x xddot`` plus the centripetal terms of a
  non-diagonal frame mass matrix ``M_x`` (:func:`frame_mass_matrix`).
* ``F`` are the applied forces (gravity, springs, forces, torques, process
  loads; force and moment about the body-frame origin).
* ``-Phi_x^T lambda`` are the constraint forces on the bodies; a joint's rows
  give its reaction.
* ``tau`` is the torque (N m) or force (N) the drive must APPLY to each driven
  coordinate -- positive when it acts in the positive sense of the coordinate.

Sign conventions (also in ``docs/kinetostatics.md``, section "Reactions and
driving torques"):

* The reaction of a joint is the force ON THE CHILD body FROM THE PARENT, at the
  joint point (revolute: the child point; prismatic: the child point; lock: the
  child frame origin), in the ground frame; the parent receives the opposite.
  Prismatic joints and locks also carry a moment on the child about that point.
* ``Drive`` elements on a driven coordinate are REPLACED by the prescribed
  motion (``model_drives="replace"``, default): ``driving`` is then the whole
  torque the motor must deliver.  With ``model_drives="load"`` they act as
  known loads and ``driving`` is the extra torque needed on top of them.
  Drives on coordinates that are not driven always act as known loads.
* The frame loads are what the FRAME RECEIVES from the mechanism: minus the
  reaction of every joint to the ground, the reaction torque of the drives on
  their stator (a drive of an absolute crank angle puts ``-tau`` on the frame),
  and the ground ends of springs, rotary springs and torques attached to it.
  Their sum is the shaking force and the shaking moment about ``point``.
  ``Force`` loads (e.g. a punch force) are external: their reaction is not
  carried by the frame unless named in ``reacting_loads``.

Where the parts live: :func:`kinetostatics` here, the analysis in one mode (the
motion specifications, the batched solve) in
:mod:`~mechdyn.dynamics.kinetostatics_mode`;
the applied loads in :mod:`~mechdyn.dynamics.forces` (the same batched code as
forward dynamics); the inertia forces in :mod:`~mechdyn.dynamics.inertia`; poses,
rates and accelerations of the prescribed motion in
:mod:`~mechdyn.dynamics.prescribed_motion`; the multiplier solve, reactions and
frame loads in :mod:`~mechdyn.dynamics.reactions`; the record
:class:`~mechdyn.results.kinetostatics_record.Kinetostatics` in ``results``.
All public names are importable from this module.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..model import as_model
from ..results.kinetostatics_record import Kinetostatics
from .forces import applied_forces
from .inertia import frame_mass_matrix, inertia_forces
from .kinetostatics_mode import _kinetostatics
from .kinetostatics_switched import kinetostatics_switched
from .prescribed_motion import dead_centres
from .reactions import KinetostaticsWarning

__all__ = ["Kinetostatics", "kinetostatics", "inertia_forces", "frame_mass_matrix",
           "applied_forces", "dead_centres", "KinetostaticsWarning"]


# ================================================================ motion specs
def kinetostatics(mech_or_model, *, over: str | Sequence[str] | None = None,
                  speed=None, values=None, t=None, law: Callable | None = None,
                  start=None, trajectory=None, hold: Mapping[str, float] | None = None,
                  mode=None, point=(0.0, 0.0), model_drives: str = "replace",
                  reacting_loads: Sequence[str] = (), x_guess=None) -> Kinetostatics:
    """Driving torques, joint reactions and frame loads for a prescribed motion.

    Give the motion in one of three ways:

    * ``speed`` (constant, rad/s or m/s; 0 for statics) and ``values`` of the
      coordinate(s) ``over`` (default one full turn, ``linspace(0, 2 pi, 361)``);
      time is ``(values - values[0]) / speed``.
    * ``t`` with ``law`` (a callable q(t) giving the driven value(s), or a
      tuple (q, qdot, qddot) for exact derivatives; derivatives are otherwise
      taken by 5-point central differences), or ``t`` with a callable ``speed``
      omega(t), integrated from ``start`` (default the sketch value).
    * ``trajectory``: an object with ``t``, ``q``, ``qdot``, ``qddot`` (and
      optionally ``x``), e.g. a :class:`~mechdyn.results.trajectory.Trajectory`
      from forward dynamics; all independent coordinates are driven.

    When the mechanism has more degrees of freedom (in ``mode``) than driven
    coordinates, the remaining coordinates are HELD at ``hold[name]`` (default
    their value in the assembled sketch); they are driven coordinates with zero
    speed and get a holding torque.  Coordinates that are fixed by the others
    in ``mode`` (e.g. the rocker angle when the rocker is locked to the slider)
    follow from the constraints.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    over : str or sequence of str, optional
        Driven coordinate(s); default the first independent coordinate.
    speed : float, array_like or callable, optional
    values : array_like, shape (n,) or (n, k), optional
        Positions of the ``over`` coordinates, rad or m.
    t : array_like, shape (n,), optional
        Times for ``law`` or a callable ``speed``, s.
    law : callable, optional
    start : float or array_like, optional
        Start value for a callable ``speed``.
    trajectory : object, optional
    hold : mapping, optional
        Values (rad or m) at which non-driven independent coordinates are held.
    mode : iterable of str, optional
        Engaged locks (default: the model's initial mode).
    point : (float, float)
        Point of the frame moments (shaking moment), ground frame, m.
    model_drives : {"replace", "load"}
        What to do with ``Drive`` elements on driven coordinates (see module
        docstring).
    reacting_loads : sequence of str
        ``Force`` loads whose reaction the frame carries (e.g. the punch force
        of a press whose bed is part of the frame).
    x_guess : array_like, shape (n_x,) or (n, n_x), optional
        Start pose(s) of the position solve (default the assembled sketch).

    Returns
    -------
    Kinetostatics

    Raises
    ------
    ModelError
        Unknown coordinate or load names, or a motion that does not fit the
        mechanism's degrees of freedom.
    AssemblyError
        A position cannot be assembled.

    Examples
    --------
    >>> import numpy as np, mechdyn as md
    >>> m = md.Mechanism("crank", gravity=(0.0, -9.81))
    >>> _ = m.add_body("crank", mass=1.0, com=(0.1, 0.0))
    >>> _ = m.add_revolute("O", "ground", "crank")
    >>> _ = m.add_coordinate("phi", kind="angle", body="crank")
    >>> res = kinetostatics(m, over="phi", speed=0.0, values=[0.0])
    >>> round(float(res.driving["phi"][0]), 4)   # holds the weight: 1 kg x 9.81 x 0.1 m
    0.981
    """
    model = as_model(mech_or_model)
    if model_drives not in ("replace", "load"):
        raise ValueError(f"model_drives must be 'replace' or 'load', got {model_drives!r}")
    vs = _variable_structure(trajectory)
    if vs is not None:
        if any(v is not None for v in (speed, values, t, law)):
            raise ValueError("give either trajectory= or speed/values/t/law, not both")
        if mode is not None:
            raise ValueError("mode= cannot be given with a variable-structure trajectory: "
                             "each sample is analysed in its recorded mode")
        return kinetostatics_switched(model, trajectory, vs, over=over, point=point,
                                      model_drives=model_drives,
                                      reacting_loads=reacting_loads)
    return _kinetostatics(model, over=over, speed=speed, values=values, t=t, law=law,
                          start=start, trajectory=trajectory, hold=hold, mode=mode,
                          point=point, model_drives=model_drives,
                          reacting_loads=reacting_loads, x_guess=x_guess)


def _variable_structure(trajectory):
    """The per-sample modes of a switched run (``trajectory.switching``), else None."""
    vs = getattr(trajectory, "switching", None) if trajectory is not None else None
    if vs is None:
        return None
    if len(vs.mode) != np.size(trajectory.t):
        raise ValueError("the trajectory's variable_structure record does not match its "
                         f"samples ({len(vs.mode)} modes for {np.size(trajectory.t)} "
                         f"samples)")
    return vs
