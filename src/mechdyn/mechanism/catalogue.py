"""A small catalogue of induction motors, every value with its source and confidence.

The 4A series is the Soviet/CIS standard series of squirrel-cage induction motors
(GOST 19523-81); the source paper of mechdyn (the clutchless press, §1 of
docs/references.md [1]) drives its crank with the motor **4A80B4U3**.  The reference for
the series is the handbook

    A. E. Kravchik, M. M. Shlaf, V. I. Afonin, E. A. Sobolenskaya,
    *Asinkhronnye dvigateli serii 4A: Spravochnik* (Induction motors of the 4A
    series: a handbook), Moscow: Energoizdat, 1982.

which could **not** be consulted while writing this module.  Each value below
therefore carries a confidence:

``"stated"``
    given by the task brief of mechdyn for the source paper's motor;
``"medium"``
    from the widely reproduced 4A tables (machine-design course books), written
    from memory: verify against the handbook before design use;
``"unconfirmed"``
    an estimate; must be checked.

Designations: ``4A`` series, ``80`` shaft height (mm), ``B`` core length, ``4``
poles (1500 rpm synchronous at 50 Hz), ``U3`` climate/placement category.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

from ..errors import ModelError, did_you_mean
from .motors import InductionMotor

__all__ = ["CatalogueEntry", "MOTORS", "catalogue_entry", "induction_motor", "list_motors",
           "KRAVCHIK_1982"]

KRAVCHIK_1982 = ("Kravchik A. E. et al., Asinkhronnye dvigateli serii 4A: Spravochnik, "
                 "Moscow: Energoizdat, 1982 (not consulted; values from memory of the "
                 "standard 4A tables)")
_BRIEF = "mechdyn task brief for the source paper's motor (press paper, docs/references.md [1])"

_RPM = math.pi / 30.0


@dataclass(frozen=True)
class CatalogueEntry:
    """Catalogue data of one induction motor (SI units; rpm kept for display).

    Parameters
    ----------
    designation : str
    rated_power : float
        W.
    synchronous_rpm : float
        rev/min.
    rated_slip : float
        s_n, dimensionless.
    breakdown_ratio, starting_ratio : float
        M_k / M_n and M_start / M_n.
    rotor_inertia : float or None
        kg m^2; None when not known.
    quoted_rated_rpm : float or None
        Rated speed as quoted alongside (may be rounded; the slip is used).
    sources : dict
        Field -> (source, confidence).
    note : str
    """

    designation: str
    rated_power: float
    synchronous_rpm: float
    rated_slip: float
    breakdown_ratio: float
    starting_ratio: float
    rotor_inertia: float | None
    quoted_rated_rpm: float | None = None
    sources: dict = field(default_factory=dict)
    note: str = ""

    def motor_kwargs(self, warn: bool = True) -> dict:
        """Keyword arguments of :class:`~mechdyn.mechanism.motors.InductionMotor` (SI);
        ``warn``: warn when the rotor inertia is not in the catalogue (taken as 0)."""
        if self.rotor_inertia is None and warn:
            warnings.warn(f"motor {self.designation}: the rotor inertia is not in the "
                          f"catalogue; it is taken as 0 - give rotor_inertia", stacklevel=3)
        return {"rated_power": self.rated_power,
                "synchronous_speed": self.synchronous_rpm * _RPM,
                "rated_slip": self.rated_slip,
                "breakdown_ratio": self.breakdown_ratio,
                "starting_ratio": self.starting_ratio,
                "rotor_inertia": 0.0 if self.rotor_inertia is None else self.rotor_inertia}

    def source_text(self) -> str:
        """Sources and confidences, one ``field: source [confidence]`` per item."""
        return "; ".join(f"{k}: {s} [{c}]" for k, (s, c) in self.sources.items())

    def confidence(self, fld: str) -> str:
        """Confidence of one field ("stated", "medium", "unconfirmed" or "unknown")."""
        return self.sources.get(fld, ("", "unknown"))[1]


def _entry(designation, kw, slip, lam, start):
    """A 4-pole motor of the 4A tables (confidence "medium"), rotor inertia not known."""
    fields = ("rated_power", "synchronous_rpm", "rated_slip", "breakdown_ratio",
              "starting_ratio")
    sources = {f: (KRAVCHIK_1982, "medium") for f in fields}
    sources["rotor_inertia"] = ("not known", "unknown")
    return CatalogueEntry(designation, kw * 1e3, 1500.0, slip, lam, start, None, None, sources)


#: the motors, by designation
MOTORS: dict[str, CatalogueEntry] = {
    "4A80B4U3": CatalogueEntry(
        "4A80B4U3", 1500.0, 1500.0, 0.058, 2.2, 2.0, 0.0033, 1415.0,
        {**{f: (_BRIEF, "stated") for f in ("rated_power", "synchronous_rpm", "rated_slip",
                                            "quoted_rated_rpm", "breakdown_ratio",
                                            "starting_ratio")},
         "rotor_inertia": ("estimate of about 0.0033 kg m^2 (task brief)", "unconfirmed")},
        note="the motor of the source paper (press, docs/references.md [1]). The slip "
             "5.8 % gives "
             "1413 rpm; the quoted 1415 rpm is a rounded catalogue speed (slip 5.67 %). "
             "mechdyn uses the slip."),
    "4A80A4U3": _entry("4A80A4U3", 1.1, 0.054, 2.2, 2.0),
    "4A90L4U3": _entry("4A90L4U3", 2.2, 0.051, 2.4, 2.1),
    "4A100S4U3": _entry("4A100S4U3", 3.0, 0.044, 2.4, 2.0),
}


def list_motors() -> list[str]:
    """Designations in the catalogue."""
    return list(MOTORS)


def catalogue_entry(designation: str) -> CatalogueEntry:
    """The entry of a motor; a clear error lists the designations known.

    Latin and Cyrillic letters are both accepted (``4А80В4У3``).
    """
    key = designation.strip().upper().translate(str.maketrans("АВУ", "ABU"))
    try:
        return MOTORS[key]
    except KeyError:
        raise ModelError(did_you_mean(designation, MOTORS, "catalogue motor")) from None


def induction_motor(designation: str, characteristic: str = "kloss", **overrides):
    """An :class:`~mechdyn.mechanism.motors.InductionMotor` from the catalogue.

    Parameters
    ----------
    designation : str
        E.g. ``"4A80B4U3"``.
    characteristic : {"kloss", "extended"}
    **overrides
        Any InductionMotor field (SI), e.g. ``rotor_inertia=0.0035``, ``name``, ``source``.
    """
    entry = catalogue_entry(designation)
    kw = {"name": entry.designation, "source": entry.source_text(),
          **entry.motor_kwargs(warn="rotor_inertia" not in overrides), **overrides}
    if "rated_speed" in overrides and "rated_slip" not in overrides:
        kw.pop("rated_slip")  # the given rated speed replaces the catalogue slip
    return InductionMotor(characteristic=characteristic, **kw)
