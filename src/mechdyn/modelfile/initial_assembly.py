"""Reading the ``[initial]``, ``[initial_speed]`` and ``[[assembly]]`` tables of a model file.

Private names
-------------
_InitialAssembly
    The readers of the initial coordinates or rates (SI values by coordinate
    name) and of one assembly mode (three points and the turn at the middle one).
"""

from __future__ import annotations

from ..errors import did_you_mean
from ..mechanism import Mechanism
from .reader import _Failed, _Reader


class _InitialAssembly(_Reader):
    """Reads the initial values and the assembly modes."""

    def initial(self, section: str, rate: bool) -> dict[str, float]:
        out: dict[str, float] = {}
        for cname, val in self.section(section).items():
            if self.broken(section, cname):
                continue
            if cname not in self.coord_kinds:
                self.problem(f"{self.where(section, cname)}: "
                             + did_you_mean(cname, self.coord_kinds, "coordinate"))
                continue
            try:
                out[cname] = self.quantity(val, self.coord_value_kind(cname, rate),
                                           section, cname)
            except _Failed:
                pass
        return out

    # ------------------------------------------------------------ assembly modes
    def assembly_mode(self, mech: Mechanism, k: int, spec: dict) -> None:
        """An [[assembly]] entry: points "body.point" P, Q, R and the turn at Q."""
        pts = []
        for i, text in enumerate(spec.get("points", [])):
            body, _, point = str(text).partition(".")
            if not point:
                self.problem(f"{self.where('assembly', k, 'points', i)}: {text!r}: write a "
                             "point as \"body.point\", e.g. \"rod.B\"")
                return
            pts.append((body, point))
        if len(pts) != 3 or "turn" not in spec:
            return
        name = spec.get("name") or f"{pts[1][0]}.{pts[1][1]}"
        mech.add_assembly_mode(name, *pts, turn=spec["turn"])
