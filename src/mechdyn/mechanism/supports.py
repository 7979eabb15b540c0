"""The supports of a machine's base: anchor bolts, isolators, and the :class:`Foundation`.

The plane is the machine's: x horizontal, y vertical (up), SI units, radians.  A
support is a linear spring (and dashpot, for an isolator) between one point of the
base and the floor, acting in x and in y.  Anchor bolts stand vertical: their axial
direction is y, their shear direction x.

The base is a rigid body on its supports; its stiffness about a reference point
(x0, y0) for the small displacement u = (ux, uy, theta) of that point is

    K = sum_i T_i^T k_i T_i,   T_i = [[1, 0, -(y_i - y0)], [0, 1, x_i - x0]],
    k_i = diag(kx_i, ky_i),

which must be non-singular for the supports to hold the base.

These are elements of the machine's description (``Mechanism.foundation``, the model
file's ``[foundation]`` table); the analyses that use them are in
:mod:`mechdyn.foundation`, which exports them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError

__all__ = ["AnchorBolt", "Isolator", "Foundation", "support_matrix"]


def _problems(owner: str, strict: bool, unit: str, **values) -> list[str]:
    """The fields of ``owner`` among ``values`` that are not finite numbers > 0 (``strict``)
    or >= 0 (``unit`` names what is expected, e.g. "force >= 0 N")."""
    return [f"{owner}: {key} must be a finite {unit}, got {value!r}"
            for key, value in values.items()
            if not (isinstance(value, int | float) and not isinstance(value, bool)
                    and math.isfinite(value) and (value > 0 if strict else value >= 0))]


def _finite(owner: str, **values) -> list[str]:
    return [f"{owner}: {key} must be a finite number, got {value!r}"
            for key, value in values.items()
            if not (isinstance(value, int | float) and math.isfinite(value))]


@dataclass(frozen=True)
class AnchorBolt:
    """A vertical anchor bolt between the base and the floor.

    Parameters
    ----------
    name : str
        Unique name of the support.
    x, y : float
        Where the bolt holds the base, m.
    k_axial : float
        Axial (y) stiffness of the bolted joint, N/m, > 0.
    k_shear : float
        Shear (x) stiffness, N/m, > 0.
    preload : float
        Tension the bolt is tightened to, N, >= 0.
    load_factor : float or None
        Share of an external axial load that goes into the bolt while the joint is
        closed (VDI 2230's Phi, 0..1).  None (default): the bounds on the safe side,
        bolt tension ``preload + max(share, 0)`` and clamp force ``preload - share``.

    Raises
    ------
    ModelError
        A non-positive stiffness, a negative preload, a load factor outside [0, 1],
        naming the bolt and the field.

    Examples
    --------
    >>> AnchorBolt("bolt1", -0.4, 0.0, k_axial=2e8, k_shear=1e8, preload=2e4).stiffness
    (100000000.0, 200000000.0)
    """

    name: str
    x: float
    y: float
    k_axial: float
    k_shear: float
    preload: float = 0.0
    load_factor: float | None = None

    def __post_init__(self):
        who = f"anchor bolt {self.name!r}"
        problems = (_finite(who, x=self.x, y=self.y)
                    + _problems(who, True, "positive number", k_axial=self.k_axial,
                                k_shear=self.k_shear)
                    + _problems(who, False, "force >= 0 N", preload=self.preload))
        if self.load_factor is not None and not 0.0 <= self.load_factor <= 1.0:
            problems.append(f"{who}: load_factor must be in [0, 1], got {self.load_factor!r}")
        if problems:
            raise ModelError(problems)

    @property
    def stiffness(self) -> tuple[float, float]:
        """(kx, ky) = (k_shear, k_axial), N/m."""
        return (float(self.k_shear), float(self.k_axial))

    @property
    def damping(self) -> tuple[float, float]:
        """(cx, cy): a bolt has none, N s/m."""
        return (0.0, 0.0)


@dataclass(frozen=True)
class Isolator:
    """A vibration isolator (elastic mount) between the base and the floor.

    Parameters
    ----------
    name : str
        Unique name of the support.
    x, y : float
        Where the isolator holds the base, m.
    kx, ky : float
        Horizontal and vertical stiffness, N/m, > 0.
    cx, cy : float
        Horizontal and vertical viscous damping, N s/m, >= 0.

    Raises
    ------
    ModelError
        A non-positive stiffness or a negative damping, naming the isolator and the field.

    Examples
    --------
    >>> Isolator("left", -0.5, 0.0, kx=1e5, ky=2e5, cy=800.0).damping
    (0.0, 800.0)
    """

    name: str
    x: float
    y: float
    kx: float
    ky: float
    cx: float = 0.0
    cy: float = 0.0

    def __post_init__(self):
        who = f"isolator {self.name!r}"
        problems = (_finite(who, x=self.x, y=self.y)
                    + _problems(who, True, "positive number", kx=self.kx, ky=self.ky)
                    + _problems(who, False, "damping >= 0 N*s/m", cx=self.cx, cy=self.cy))
        if problems:
            raise ModelError(problems)

    @property
    def stiffness(self) -> tuple[float, float]:
        """(kx, ky), N/m."""
        return (float(self.kx), float(self.ky))

    @property
    def damping(self) -> tuple[float, float]:
        """(cx, cy), N s/m."""
        return (float(self.cx), float(self.cy))


Support = AnchorBolt | Isolator


def support_matrix(supports: Sequence[Support], reference=(0.0, 0.0)) -> np.ndarray:
    """The kinematic matrices T_i of the supports, shape (n, 2, 3).

    Row 0 of ``T_i`` gives the x displacement, row 1 the y displacement of the support
    point for the small displacement (ux, uy, theta) of the base at ``reference``.

    Examples
    --------
    >>> bolt = AnchorBolt("b", 1.0, 0.5, 1.0, 1.0)
    >>> support_matrix([bolt]).tolist()
    [[[1.0, 0.0, -0.5], [0.0, 1.0, 1.0]]]
    """
    x0, y0 = (float(v) for v in reference)
    T = np.zeros((len(supports), 2, 3))
    for i, s in enumerate(supports):
        T[i] = [[1.0, 0.0, -(s.y - y0)], [0.0, 1.0, s.x - x0]]
    return T


@dataclass(frozen=True)
class Foundation:
    """The machine's frame as a rigid base on N supports.

    Parameters
    ----------
    supports : sequence of AnchorBolt or Isolator
        At least two, at distinct points (the base needs stiffness in x, y and rotation).
    mass : float, optional
        Mass of the frame and base, kg (only the elastic analysis needs it).
    inertia : float, optional
        Moment of inertia of the frame and base about their centre of mass, kg m^2.
    com : (float, float)
        Centre of mass of the frame and base, m.

    Raises
    ------
    ModelError
        Duplicate support names, a non-positive mass or inertia, or supports that cannot
        hold the base (the missing direction named: e.g. a rotation about the one point
        all supports share).

    Examples
    --------
    >>> f = Foundation([AnchorBolt("b1", -0.4, 0.0, 2e8, 1e8),
    ...                 AnchorBolt("b2", 0.4, 0.0, 2e8, 1e8)])
    >>> f.names
    ('b1', 'b2')
    >>> np.round(f.stiffness_matrix(), 3).tolist()
    [[200000000.0, 0.0, 0.0], [0.0, 400000000.0, 0.0], [0.0, 0.0, 64000000.0]]
    """

    supports: tuple
    mass: float | None = None
    inertia: float | None = None
    com: tuple = field(default=(0.0, 0.0))

    def __post_init__(self):
        object.__setattr__(self, "supports", tuple(self.supports))
        object.__setattr__(self, "com", tuple(float(v) for v in self.com))
        problems = []
        bad = [s for s in self.supports if not isinstance(s, AnchorBolt | Isolator)]
        if bad:
            problems.append(f"foundation: supports must be AnchorBolt or Isolator, got "
                            f"{type(bad[0]).__name__}")
        seen: set = set()
        for s in self.supports:
            name = getattr(s, "name", None)
            if name in seen:
                problems.append(f"foundation: support name {name!r} is used twice")
            seen.add(name)
        problems += _problems("foundation", True, "positive number", **{
            key: getattr(self, key) for key in ("mass", "inertia")
            if getattr(self, key) is not None})
        if len(self.com) != 2 or not all(math.isfinite(v) for v in self.com):
            problems.append(f"foundation: com must be a finite (x, y) in m, got {self.com!r}")
        if problems:
            raise ModelError(problems)
        if not self.supports:
            raise ModelError("foundation: no supports; the base needs at least two at "
                             "distinct points to be held in x, y and rotation")
        self._check_held()

    def _check_held(self) -> None:
        """Raise if the stiffness of the base is singular, naming the free direction."""
        K = self.stiffness_matrix()
        scale = np.sqrt(np.abs(np.diag(K)))
        scale[scale == 0] = 1.0
        w, v = np.linalg.eigh(K / np.outer(scale, scale))
        if w[0] > 1e-9 * w[-1]:
            return
        ux, uy, th = v[:, 0] / scale
        if abs(th) > 1e-9 * max(abs(ux), abs(uy)):
            free = f"rotation about ({-uy / th + 0.0:.6g}, {ux / th + 0.0:.6g}) m"
        else:
            free = f"translation along ({ux / math.hypot(ux, uy):.3g}, " \
                   f"{uy / math.hypot(ux, uy):.3g})"
        raise ModelError(f"foundation: the supports {', '.join(self.names)} cannot hold the "
                         f"base: nothing resists a {free}; add a support at another point")

    @property
    def names(self) -> tuple[str, ...]:
        """Support names, in order."""
        return tuple(s.name for s in self.supports)

    @property
    def bolts(self) -> tuple[bool, ...]:
        """True for each support that is an anchor bolt."""
        return tuple(isinstance(s, AnchorBolt) for s in self.supports)

    def positions(self) -> np.ndarray:
        """(x, y) of every support, shape (n, 2), m."""
        return np.array([(s.x, s.y) for s in self.supports], float)

    def stiffnesses(self) -> np.ndarray:
        """(kx, ky) of every support, shape (n, 2), N/m."""
        return np.array([s.stiffness for s in self.supports], float)

    def dampings(self) -> np.ndarray:
        """(cx, cy) of every support, shape (n, 2), N s/m."""
        return np.array([s.damping for s in self.supports], float)

    def stiffness_matrix(self, reference=None) -> np.ndarray:
        """K = sum T_i^T diag(kx_i, ky_i) T_i, shape (3, 3), about ``reference`` (default
        the origin), for (ux, uy, theta): N/m, N/rad, N m/rad."""
        return _assemble(self.supports, self.stiffnesses(), reference)

    def damping_matrix(self, reference=None) -> np.ndarray:
        """C = sum T_i^T diag(cx_i, cy_i) T_i, shape (3, 3), about ``reference``."""
        return _assemble(self.supports, self.dampings(), reference)

    def mass_matrix(self) -> np.ndarray:
        """diag(m, m, J) of the base about its centre of mass, shape (3, 3).

        Raises
        ------
        ModelError
            ``mass`` or ``inertia`` not given.
        """
        missing = [k for k in ("mass", "inertia") if getattr(self, k) is None]
        if missing:
            raise ModelError(f"foundation: the elastic analysis needs the {' and '.join(missing)}"
                             f" of the frame and base (Foundation(..., mass=..., inertia=...))")
        return np.diag([float(self.mass), float(self.mass), float(self.inertia)])


def _assemble(supports, k, reference) -> np.ndarray:
    T = support_matrix(supports, (0.0, 0.0) if reference is None else reference)
    return np.einsum("nki,nk,nkj->ij", T, k, T)
