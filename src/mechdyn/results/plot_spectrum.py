"""Plot of a history and its content in frequency: the signal, its amplitude spectrum and
its spectrogram (a start-up or switching transient shows where its content changes)."""

from __future__ import annotations

from pathlib import Path

from .figure import figure as _figure
from .figure import save as _save
from .spectrum import history, spectrogram, spectrum
from .table import unit_of_column

__all__ = ["plot_spectrum"]


def plot_spectrum(record, column: str, path, *, f_max: float | None = None,
                  segment: float | None = None, dpi: int = 120) -> Path:
    """Plot a column of a record's table against time, its amplitude spectrum and its
    spectrogram.

    Parameters
    ----------
    record
        A record with ``to_dataframe()`` and a ``t_s`` column (a Trajectory).
    column : str
        E.g. ``"Fy_frame_N"``.
    path : str or Path
        Image file (format from the suffix).
    f_max : float, optional
        Highest frequency shown, Hz (default: all).
    segment : float, optional
        Segment length of the spectrogram, s (default 1/8 of the run).
    dpi : int

    Returns
    -------
    Path

    Raises
    ------
    KeyError
        An unknown column (the valid ones are listed).
    """
    t, y = history(record, column)
    unit = unit_of_column(column) or "-"
    sp = spectrum(t, y)
    f, tc, amp = spectrogram(t, y, segment=segment)
    top = f_max if f_max is not None else float(sp["f_Hz"].iloc[-1])
    fig, ax = _figure(3, height=2.6, sharex=False)
    ax[0].plot(t, y, lw=1.0)
    ax[0].set_xlabel("t (s)")
    ax[0].set_ylabel(f"{column} ({unit})")
    keep = sp["f_Hz"] <= top
    ax[1].plot(sp["f_Hz"][keep], sp["amplitude"][keep], lw=1.0)
    ax[1].set_xlabel("frequency (Hz)")
    ax[1].set_ylabel(f"amplitude ({unit})")
    rows = f <= top
    mesh = ax[2].pcolormesh(tc, f[rows], amp[rows], shading="nearest")
    ax[2].set_xlabel("t (s)")
    ax[2].set_ylabel("frequency (Hz)")
    fig.colorbar(mesh, ax=ax[2], label=f"amplitude ({unit})")
    fig.suptitle(f"{column}: history, spectrum and spectrogram")
    return _save(fig, Path(path), dpi)

