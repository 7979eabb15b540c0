"""The warning of an analysis that does not model the friction of the pairs yet, run on a
model that has it (issue 12: an analysis must not ignore friction silently).

The analyses that model it (kinetostatics, ``docs/friction.md``) need nothing from here;
the others call :func:`warn_friction_ignored` once per run, naming the joints and what
their result leaves out.
"""

from __future__ import annotations

import warnings

from ..model import Model
from .law import friction_joints

__all__ = ["FrictionIgnoredWarning", "friction_text", "warn_friction_ignored"]


class FrictionIgnoredWarning(UserWarning):
    """An analysis that does not model the friction of the pairs ran on a model with
    friction: its result is that of the frictionless machine."""


def _joint_text(joint) -> str:
    kind = "pin_radius" if hasattr(joint, "pin_radius") else "guide_length"
    parts = []
    if joint.friction > 0:
        parts.append(f"friction = {joint.friction:.6g} ({kind} "
                     f"{getattr(joint, kind) * 1e3:.6g} mm)")
    if joint.viscous > 0:
        parts.append(f"viscous = {joint.viscous:.6g} "
                     + ("N m s/rad" if kind == "pin_radius" else "N s/m"))
    return f"joint {joint.name!r} has " + " and ".join(parts)


def friction_text(model: Model) -> str:
    """What the pairs of ``model`` with friction carry, one clause a joint ('' without).

    Examples
    --------
    >>> import mechdyn
    >>> m = mechdyn.examples.load("toggle_press_friction").compile()
    >>> friction_text(m).split("; ")[0]
    "joint 'A' has friction = 0.08 (pin_radius 40 mm)"
    """
    joints = model.mechanism.joints
    return "; ".join(_joint_text(joints[n]) for n in friction_joints(model))


def warn_friction_ignored(model: Model, analysis: str, left_out: str, *,
                          stacklevel: int = 3) -> tuple[str, ...]:
    """Warn once that ``analysis`` does not model the friction of ``model``'s pairs.

    Parameters
    ----------
    model : Model
    analysis : str
        The analysis, as the user calls it (e.g. ``"the reduction method"``).
    left_out : str
        What its result leaves out.
    stacklevel : int
        As :func:`warnings.warn`, counted from the caller of this function.

    Returns
    -------
    tuple of str
        The joints with friction (empty: no warning).

    Examples
    --------
    >>> import mechdyn
    >>> m = mechdyn.examples.load("slider_crank").compile()
    >>> warn_friction_ignored(m, "an analysis", "nothing")
    ()
    """
    names = friction_joints(model)
    if names:
        warnings.warn(f"{friction_text(model)}; {analysis} does not model friction yet: "
                      f"{left_out}", FrictionIgnoredWarning, stacklevel=stacklevel + 1)
    return names
