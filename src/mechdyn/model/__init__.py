"""The compiled model: index layout, parameter arrays and constraint rows.

:mod:`mechdyn.model.compile` holds :class:`Model`; :mod:`mechdyn.model.rows`
the lowering rules that turn every joint, coordinate, lock, stop and contact
into constraint rows of one form.
"""

from .compile import (
    COORD_ANGLE,
    COORD_RELATIVE,
    COORD_TRAVEL,
    COORD_X,
    COORD_Y,
    ConstraintLayout,
    Model,
    as_model,
)

__all__ = ["Model", "ConstraintLayout", "as_model", "COORD_ANGLE", "COORD_RELATIVE",
           "COORD_TRAVEL", "COORD_X", "COORD_Y"]
