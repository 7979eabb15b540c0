"""Kinetostatics (inverse dynamics for a given motion): driving torques, joint
reactions, and the loads the frame and foundation receive.

Driving constraints ``g_d(x) - q_d(t) = 0`` are appended to the joint constraints
``Phi(x) = 0``; with the poses and their rates known, one linear solve per position
(batched over all positions) gives the multipliers and the driving torques::

    -Phi_x^T lambda + g_d,x^T tau = I(x, xdot, xddot) - F(t, x, xdot)

(``I`` the inertia forces, ``F`` the applied forces).  With friction in the pairs
``F`` also holds their friction, which depends on the reactions: the system becomes
nonlinear and is solved by Newton's method per position
(:mod:`~mechdyn.friction.kinetostatic`, ``docs/friction.md``), which also
finds the self-locking positions.  The sign conventions of
reactions, driving torques and frame loads, and the two ways of treating ``Drive``
elements (``model_drives``), are stated once, in ``docs/kinetostatics.md``, section
"Reactions and driving torques".

Where the parts live: :func:`kinetostatics` here; the analysis in one mode in
:mod:`~mechdyn.kinetostatics.mode`, of a switched trajectory in
:mod:`~mechdyn.kinetostatics.switched`; poses, rates and accelerations in
:mod:`~mechdyn.kinetostatics.prescribed`; the multiplier solve, reactions and frame
loads in :mod:`~mechdyn.dynamics.reactions`; the record
:class:`~mechdyn.results.kinetostatics_record.Kinetostatics` in ``results``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from ..dynamics.reactions import KinetostaticsWarning
from ..model import as_model
from ..model.forces import applied_forces
from ..model.inertia import frame_mass_matrix, inertia_forces
from ..results.kinetostatics_record import Kinetostatics
from .mode import _kinetostatics
from .prescribed import dead_centres
from .switched import kinetostatics_switched

__all__ = ["Kinetostatics", "kinetostatics", "inertia_forces", "frame_mass_matrix",
           "applied_forces", "dead_centres", "KinetostaticsWarning"]


def kinetostatics(mech_or_model, *, over: str | Sequence[str] | None = None,
                  speed=None, values=None, t=None, law: Callable | None = None,
                  start=None, trajectory=None, hold: Mapping[str, float] | None = None,
                  mode=None, point=(0.0, 0.0), model_drives: str = "replace",
                  reacting_loads: Sequence[str] = (), x_guess=None) -> Kinetostatics:
    """Driving torques, joint reactions and frame loads for a prescribed motion.

    Give the motion in one of three ways:

    * ``speed`` (constant, 0 for statics: a number in rad/s or m/s, a unit text such as
      ``"60 rpm"`` or ``"0.5 m/s"``, or a pint quantity) and ``values`` of the
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
    speed : float, str, pint.Quantity, sequence of them, or callable, optional
        The constant speed of the driven coordinate(s), one for all or one per
        coordinate: a bare number is SI (rad/s for an angle coordinate, m/s for a length
        one); a unit text (``"60 rpm"``, ``"4.2 rad/s"``, ``"0.5 m/s"``) or a pint
        quantity is converted, an angle rate for an angle coordinate and a length rate
        for a length one.  A callable is a speed law omega(t), rad/s or m/s, with ``t``.
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
        ``Drive`` elements on driven coordinates: replaced by the prescribed motion
        (``driving`` is the whole drive torque), or known loads (``driving`` is the
        extra torque needed on top of them); drives on other coordinates are loads.
    reacting_loads : sequence of str
        ``Force`` loads whose reaction the frame carries (e.g. the punch force
        of a press whose bed is part of the frame).
    x_guess : array_like, shape (n_x,) or (n, n_x), optional
        Start pose(s) of the position solve (default the assembled sketch).

    Returns
    -------
    Kinetostatics
        With friction in the pairs (``docs/friction.md``) also the power lost in each
        pair (``losses``), the useful output power (``power_out``), the efficiencies
        (``efficiency``, ``cycle_efficiency``) and the self-locked positions
        (``locked``; status ``"self-locking"``, their torques and reactions NaN).

    Raises
    ------
    ModelError
        Unknown coordinate or load names, or a motion that does not fit the
        mechanism's degrees of freedom.
    UnitError
        A ``speed`` whose unit does not fit its coordinate (a length rate for an angle,
        a frequency in Hz for an angle rate, ...); the message names the coordinate.
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
    >>> res = kinetostatics(m, over="phi", speed="60 rpm", values=[0.0, np.pi / 2])
    >>> res.t.round(6).tolist()   # a quarter turn at 1 turn/s
    [0.0, 0.25]
    >>> kinetostatics(m, over="phi", speed="0.5 m/s", values=[0.0])
    Traceback (most recent call last):
    ...
    mechdyn.errors.UnitError: speed of 'phi' (an angle coordinate): '0.5 m/s': ... velocity unit...
    """
    model = as_model(mech_or_model)
    if model_drives not in ("replace", "load"):
        raise ValueError(f"model_drives must be 'replace' or 'load', got {model_drives!r}")
    if trajectory is not None and any(v is not None for v in (speed, values, t, law)):
        raise ValueError("give either trajectory= or speed/values/t/law, not both")
    vs = getattr(trajectory, "switching", None)
    if vs is not None:
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
