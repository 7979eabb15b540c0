"""Short reprs of the result records: the class name, the model's name, the sizes, the
status and a few key figures, in a line of at most about 300 characters (a notebook
cell showing a record prints this, not its arrays; the data stay in the fields)."""

from __future__ import annotations

import numpy as np

__all__ = ["brief", "number", "span", "status_text"]

#: the longest repr :func:`brief` gives
LIMIT = 300


def number(value, unit: str = "") -> str:
    """A figure in 4 significant digits with its unit, ``"?"`` when None.

    Examples
    --------
    >>> number(0.1234567, "m"), number(None), number(float("nan"), "J")
    ('0.1235 m', '?', 'nan J')
    """
    if value is None:
        return "?"
    text = f"{float(value):.4g}"
    return f"{text} {unit}" if unit else text


def span(values, unit: str = "", scale: float = 1.0) -> str:
    """The range ``"min .. max unit"`` of the finite values (``""`` when there are none),
    each value times ``scale``.

    Examples
    --------
    >>> span([3.0, 1.0, float("nan"), 2.0], "s")
    '1 .. 3 s'
    >>> span([])
    ''
    """
    a = np.asarray(values, float).ravel() * scale
    a = a[np.isfinite(a)]
    if a.size == 0:
        return ""
    return f"{number(a.min())} .. {number(a.max(), unit)}"


def brief(record, *parts: str, model=None) -> str:
    """The short repr of a result record: ``Class('model', part, part, ...)``.

    Parameters
    ----------
    record : object
        The record; its class names the repr.
    *parts : str
        Sizes, status and figures, in order; empty ones are left out.
    model : str, optional
        The model's name (default the name of ``record.model``'s mechanism, if any).

    Returns
    -------
    str
        At most :data:`LIMIT` characters (a longer one ends in ``...)``).

    Examples
    --------
    >>> class Sweep:
    ...     pass
    >>> brief(Sweep(), "361 positions", "", "status='success'", model="slider_crank")
    "Sweep('slider_crank', 361 positions, status='success')"
    """
    if model is None:
        mech = getattr(getattr(record, "model", None), "mechanism", None)
        model = getattr(mech, "name", None)
    items = ([repr(model)] if model else []) + [p for p in parts if p]
    text = f"{type(record).__name__}({', '.join(items)})"
    return text if len(text) <= LIMIT else text[: LIMIT - 4] + "...)"


def status_text(record) -> str:
    """``status='success'`` of a record with a ``status`` (``""`` without).

    Examples
    --------
    >>> class Run:
    ...     status = "event"
    >>> status_text(Run()), status_text(object())
    ("status='event'", '')
    """
    status = getattr(record, "status", None)
    return "" if status is None else f"status={str(status)!r}"

