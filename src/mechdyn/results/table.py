"""Result records to CSV tables.

Every record has ``to_dataframe()`` whose column names end with their SI unit
(``phi_deg``, ``vx_rod_B_m_s``, ``M_drive_Nm``; the scheme is in
``docs/notation.md``).  :func:`write_csv` writes that table with a short header
of ``#`` comment lines: what the record is, its status, and the unit of every
column in words.  :func:`read_csv` reads it back.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

__all__ = ["write_csv", "read_csv", "CsvStream", "unit_of_column", "UNIT_SUFFIXES",
           "output_path", "written", "deg_or_mm", "rate_text"]

#: column-name suffix -> unit, longest suffixes first when matching
UNIT_SUFFIXES: dict[str, str] = {
    "_rad_s2": "rad/s^2",
    "_rad_s": "rad/s",
    "_rad_m": "rad/m",
    "_rad": "rad",
    "_deg_s": "deg/s",
    "_deg": "deg",
    "_rpm": "rpm",
    "_m_s2": "m/s^2",
    "_m_s": "m/s",
    "_m_m": "m/m",
    "_m": "m",
    "_mm": "mm",
    "_Nm": "N*m",
    "_N": "N",
    "_kg_m2": "kg*m^2",
    "_kgm2": "kg*m^2",
    "_kg": "kg",
    "_J": "J",
    "_W": "W",
    "_Hz": "Hz",
    "_s": "s",
    "_1": "1",
}


def unit_of_column(name: str) -> str:
    """Unit named by a column's suffix (``"vx_rod_B_m_s"`` -> ``"m/s"``); ``""`` if none."""
    for suffix in sorted(UNIT_SUFFIXES, key=len, reverse=True):
        if name.endswith(suffix):
            return UNIT_SUFFIXES[suffix]
    return ""


def output_path(path) -> Path:
    """``path`` as a :class:`~pathlib.Path`, its folder created if needed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


@contextmanager
def written(path) -> Iterator[Path]:
    """Write a file atomically: yields a temporary path beside ``path`` (same suffix),
    which replaces ``path`` only once the block has completed; a failed or interrupted
    write leaves no half-written file and an earlier ``path`` untouched.  A path that
    is not a regular file (a device, a pipe) is written directly.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> with written(out) as tmp:
    ...     _ = tmp.write_text("a,b\\n")
    >>> out.read_text()
    'a,b\\n'
    """
    path = output_path(path)
    if path.exists() and not path.is_file():  # a device or a pipe: written as it is
        yield path
        return
    tmp = path.with_name(f".{path.stem}.part{path.suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def deg_or_mm(values, is_angle: bool) -> tuple[np.ndarray, str]:
    """Values of a coordinate in engineering units: angles in deg, lengths in mm.

    Returns
    -------
    (ndarray, str)
        The converted values and their unit, ``"deg"`` or ``"mm"``.
    """
    return (np.rad2deg(values), "deg") if is_angle else (np.asarray(values) * 1e3, "mm")


def rate_text(rate: float, is_angle: bool) -> str:
    """A constant rate as text: ``"157.08 rad/s (1500 rpm)"`` or ``"0.5 m/s"``."""
    return f"{rate:.6g} rad/s ({rate * 30 / np.pi:.6g} rpm)" if is_angle else f"{rate:.6g} m/s"


def coordinate_columns(names, is_angle, q, qdot, qddot, *, radians: bool = True,
                       degrees: bool = True) -> dict:
    """Table columns of coordinates (n, n_q) and their rates: ``<c>_rad`` (with ``radians``)
    and ``<c>_deg`` (with ``degrees``) for an angle, ``<c>_m`` for a travel, then
    ``<c>_dot_rad_s`` and ``<c>_ddot_rad_s2`` (``_m_s``, ``_m_s2``)."""
    cols = {}
    for k, c in enumerate(names):
        u = "rad" if is_angle[k] else "m"
        if radians or u == "m":
            cols[f"{c}_{u}"] = q[:, k]
        if degrees and u == "rad":
            cols[f"{c}_deg"] = np.rad2deg(q[:, k])
        cols[f"{c}_dot_{u}_s"] = qdot[:, k]
        cols[f"{c}_ddot_{u}_s2"] = qddot[:, k]
    return cols


def force_columns(key: str, f, *, magnitude: bool = False) -> dict:
    """Table columns of a force: ``F_<key>_N`` of shape (n,); ``Fx_<key>_N``, ``Fy_<key>_N``
    (and ``F_<key>_N`` with ``magnitude``) of (n, 2); and ``M_<key>_Nm`` of a third column."""
    f = np.asarray(f, float)
    if f.ndim == 1:
        return {f"F_{key}_N": f}
    cols = {f"Fx_{key}_N": f[:, 0], f"Fy_{key}_N": f[:, 1]}
    if magnitude:
        cols[f"F_{key}_N"] = np.hypot(f[:, 0], f[:, 1])
    if f.shape[1] > 2:
        cols[f"M_{key}_Nm"] = f[:, 2]
    return cols


def mode_columns(modes, mode_index) -> dict:
    """The ``mode`` (engaged elements, ``-`` for none) and ``mode_index`` of every sample."""
    return {"mode": np.array([" ".join(sorted(m)) or "-" for m in modes], dtype=object),
            "mode_index": np.asarray(mode_index)}


def write_csv(record, path, *, float_format: str = "%.12g", **options) -> Path:
    """Write a result record's table to CSV with a commented header of units.

    Parameters
    ----------
    record
        Any result record with ``to_dataframe()`` (e.g. :class:`~mechdyn.kinematics.
        sweep.KinematicSweep`).
    path : str or Path
        Output file; its folder is created if needed.
    float_format : str
        printf-style format of the numbers (default 12 significant digits).
    **options
        Passed to the record's ``to_dataframe`` (e.g. ``points=True`` for a trajectory).

    Returns
    -------
    Path
        The file written.
    """
    df = record.to_dataframe(**options)
    path = output_path(path)
    with written(path) as tmp, open(tmp, "w", encoding="utf-8", newline="") as fh:
        for line in _header(record, df.columns, outcome=True):
            fh.write(f"# {line}\n")
        df.to_csv(fh, index=False, float_format=float_format, lineterminator="\n")
    return path


def _header(record, columns, *, outcome: bool) -> list[str]:
    """The ``#`` lines of a table: the record, its status and message (with ``outcome``),
    and the unit of every column."""
    mech = getattr(getattr(record, "model", None), "mechanism", None)
    lines = [f"mechdyn {type(record).__name__}"
             + (f" of {mech.name!r}" if mech is not None else "")]
    if getattr(record, "over", None) is not None:
        lines.append(f"swept coordinate: {record.over}")
    lines.extend(_outcome(record) if outcome else [
        "rows written as they are computed; the run's outcome is on the last lines"])
    lines.append("column names end with their SI unit (see docs/notation.md); "
                 "analogs are per rad (angle coordinates) or per m (travels)")
    lines.append("units: " + ", ".join(f"{c} [{unit_of_column(c) or '-'}]" for c in columns))
    return lines


def _outcome(record) -> list[str]:
    """The status and message lines of a record."""
    lines = [] if getattr(record, "status", None) is None else [f"status: {record.status}"]
    message = getattr(record, "message", "")
    if message:
        lines.append("message: " + " ".join(str(message).split()))
    return lines


class CsvStream:
    """A table written as its rows are computed: the sink of
    :func:`mechdyn.simulate` (``sink=``).

    ``NAME.csv`` is written as ``NAME.csv.partial``: the ``#`` header and the column
    names with the first chunk, then every chunk appended in one write; :meth:`close`
    appends the status and message lines and renames the file to ``NAME.csv``.  A run that
    crashed leaves ``NAME.csv.partial``, readable by :func:`read_csv` up to its last chunk.
    A path that is not a regular file (a device, a pipe) is written directly.

    Parameters
    ----------
    path : str or Path
        The table to write; its folder is created if needed.
    table : callable, optional
        ``table(part) -> DataFrame`` of a chunk (default ``part.to_dataframe()``).
    float_format : str
        printf-style format of the numbers.

    Raises
    ------
    RuntimeError
        A chunk whose columns differ from the first one's.

    Examples
    --------
    >>> import tempfile, pathlib, mechdyn
    >>> from mechdyn import examples
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "fb.csv"
    >>> stream = CsvStream(out)
    >>> traj = mechdyn.simulate(mechdyn.load(examples.path("four_bar")), 0.01,
    ...                         t_eval=[0, 0.005, 0.01], sink=stream, chunk=2, keep=False)
    >>> stream.close(traj).name, stream.rows
    ('fb.csv', 3)
    >>> len(read_csv(out))
    3
    """

    def __init__(self, path, *, table=None, float_format: str = "%.12g"):
        self.path = output_path(path)
        direct = self.path.exists() and not self.path.is_file()
        self.partial = self.path if direct else self.path.with_name(self.path.name + ".partial")
        self.table = table or (lambda part: part.to_dataframe())
        self.float_format = float_format
        self.columns: list | None = None
        self.rows = 0
        self._fh = None

    def _write(self, text: str) -> None:
        data = memoryview(text.encode("utf-8"))
        while data:  # one write call for a chunk: a killed process leaves whole chunks
            data = data[self._fh.write(data):]

    def __call__(self, part, start: int) -> None:
        """Append the rows of ``part`` (a record with ``to_dataframe``) from row ``start``
        of the run (rows already written are skipped)."""
        df = self.table(part).iloc[max(self.rows - start, 0):]
        if self.columns is None:
            self._fh = open(self.partial, "wb", buffering=0)  # noqa: SIM115 - kept open
            self.columns = list(df.columns)
            text = "".join(f"# {line}\n" for line in _header(part, df.columns, outcome=False))
            self._write(text + ",".join(self.columns) + "\n")
        elif list(df.columns) != self.columns:
            raise RuntimeError(f"{self.path}: the columns of a chunk changed: "
                               f"{sorted(set(df.columns) ^ set(self.columns))}")
        if len(df):
            self._write(df.to_csv(None, index=False, header=False,
                                  float_format=self.float_format, lineterminator="\n"))
            self.rows += len(df)

    def close(self, record) -> Path:
        """End the table with ``record``'s status and message and give it its name.

        Parameters
        ----------
        record
            The record of the whole run (its header when no row was written).

        Returns
        -------
        Path
            The table written.
        """
        if self.columns is None:  # no chunk came: no row was computed, the header alone
            self(record, 0)
        try:
            self._write("".join(f"# {line}\n" for line in _outcome(record)))
        finally:
            self.abort()
        if self.partial != self.path:
            os.replace(self.partial, self.path)
        return self.path

    def abort(self) -> None:
        """Close the file where it is (``NAME.csv.partial`` stays as written)."""
        if self._fh is not None:
            self._fh.close()
            self._fh = None


def read_csv(path):
    """Read a table written by :func:`write_csv` into a pandas DataFrame."""
    import pandas as pd

    return pd.read_csv(path, comment="#")
