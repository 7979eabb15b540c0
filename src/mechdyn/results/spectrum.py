"""Spectra of any history of a run: a frame load, a reaction, a speed.

The samples of a run need not be uniform (every integrator step, or a switched run
with extra samples at its events): :func:`spectrum` resamples them on a uniform grid
(cubic interpolation), applies a window and gives the one-sided amplitude spectrum
with scipy's FFT, the amplitudes corrected for the window's coherent gain (a flat-top
window by default: amplitudes true to a few 1e-3 between bins).  :func:`dominant` lists
the strongest components and refines each one by least squares on the original
samples (frequency, amplitude and phase of a sum of sinusoids), which is exact for a
stationary signal.  :func:`spectrogram` (scipy.signal) shows how the content changes
through a start-up or a switching transient, and :func:`order_spectrum` gives the
harmonics of a cyclic run against the crank angle (orders of the turn), whatever the
speed fluctuation.

Examples
--------
>>> import numpy as np
>>> t = np.sort(np.random.default_rng(1).uniform(0.0, 20.0, 4000))
>>> y = 3.0 * np.sin(2 * np.pi * 7.3 * t) + 0.5 * np.cos(2 * np.pi * 23.1 * t)
>>> peaks = dominant(t, y, 2)
>>> [round(f, 4) for f in peaks["f_Hz"]], [round(a, 4) for a in peaks["amplitude"]]
([7.3, 23.1], [3.0, 0.5])
"""

from __future__ import annotations

import numpy as np

__all__ = ["spectrum", "dominant", "spectrogram", "order_spectrum", "welch", "summary",
           "history", "of_column"]


def _uniform(t, y, samples: int | None):
    """(dt, y on a uniform grid over [t0, t_end]) from samples (t, y), cubic."""
    from scipy.interpolate import CubicSpline

    t, y = np.asarray(t, float), np.asarray(y, float)
    keep = np.concatenate([[True], np.diff(t) > 0])  # repeated times (at events): keep one
    t, y = t[keep], y[keep]
    if t.size < 8:
        raise ValueError(f"a spectrum needs at least 8 distinct sample times, got {t.size}")
    n = int(samples or 2 ** int(np.ceil(np.log2(max(t.size, 256)))))
    grid = np.linspace(t[0], t[-1], n)
    return grid[1] - grid[0], CubicSpline(t, y)(grid)


def _segments(t, y, segment: float | None, samples: int | None):
    """(dt, y on a uniform grid, points per segment of ``segment`` s: 1/8 of the run)."""
    dt, u = _uniform(t, y, samples)
    return dt, u, max(8, int(round((segment or (u.size * dt) / 8) / dt)))


def spectrum(t, y, *, window: str = "flattop", samples: int | None = None):
    """One-sided amplitude spectrum of a signal sampled at times ``t`` (any spacing).

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times, s, increasing (repeated times, as at an event, are merged).
    y : array_like, shape (n,)
        The signal, in its unit (N, N m, rad/s ...).
    window : str
        A :func:`scipy.signal.get_window` name; ``"flattop"`` for true amplitudes,
        ``"hann"`` for a sharper resolution.
    samples : int, optional
        Points of the uniform grid (default the next power of two above n, at least 256).

    Returns
    -------
    pandas.DataFrame
        ``f_Hz`` and ``amplitude`` (the amplitude of a sinusoid at that frequency, in the
        unit of ``y``; the mean at 0 Hz).

    Raises
    ------
    ValueError
        Fewer than 8 distinct sample times.
    """
    import pandas as pd
    from scipy.signal import get_window

    dt, u = _uniform(t, y, samples)
    w = get_window(window, u.size)
    spec = np.abs(np.fft.rfft((u - u.mean()) * w)) * 2.0 / w.sum()
    spec[0] = abs(u.mean())
    return pd.DataFrame({"f_Hz": np.fft.rfftfreq(u.size, dt), "amplitude": spec})


def dominant(t, y, n: int = 5, *, samples: int | None = None):
    """The ``n`` strongest sinusoidal components of a signal, refined by least squares.

    The peaks of the Hann-windowed spectrum give the starting frequencies; a least-squares
    fit of ``mean + sum a_k cos(2 pi f_k t) + b_k sin(2 pi f_k t)`` to the original samples
    then gives each frequency, amplitude ``sqrt(a^2 + b^2)`` and phase.

    Parameters
    ----------
    t, y : array_like, shape (m,)
        As in :func:`spectrum`.
    n : int
        Components wanted.

    Returns
    -------
    pandas.DataFrame
        ``f_Hz``, ``amplitude`` (unit of ``y``), ``phase_rad`` (of a cosine), strongest
        first.
    """
    import pandas as pd
    from scipy.optimize import least_squares
    from scipy.signal import find_peaks

    t, y = np.asarray(t, float), np.asarray(y, float)
    sp = spectrum(t, y, window="hann", samples=samples)
    f, a = sp["f_Hz"].to_numpy(), sp["amplitude"].to_numpy()
    idx, _ = find_peaks(a[1:])
    idx = idx[np.argsort(a[1:][idx])[::-1][:n]] + 1
    f0 = f[idx]

    def basis(freqs):
        arg = 2.0 * np.pi * np.outer(t, freqs)
        return np.hstack([np.ones((t.size, 1)), np.cos(arg), np.sin(arg)])

    def residual(freqs):  # variable projection: the amplitudes are linear
        A = basis(freqs)
        return A @ np.linalg.lstsq(A, y, rcond=None)[0] - y

    freqs = least_squares(residual, f0, x_scale=np.maximum(f0, 1e-9) * 1e-3).x if f0.size \
        else f0
    coef = np.linalg.lstsq(basis(freqs), y, rcond=None)[0]
    k = freqs.size
    ca, cb = coef[1:k + 1], coef[k + 1:]
    out = pd.DataFrame({"f_Hz": freqs, "amplitude": np.hypot(ca, cb),
                        "phase_rad": np.arctan2(-cb, ca)})
    return out.sort_values("amplitude", ascending=False, ignore_index=True)


def spectrogram(t, y, *, segment: float | None = None, samples: int | None = None):
    """How the spectrum of a signal changes in time (a start-up, a switching transient).

    Parameters
    ----------
    t, y : array_like, shape (n,)
        As in :func:`spectrum`.
    segment : float, optional
        Length of each analysed segment, s (default 1/8 of the run).

    Returns
    -------
    f : ndarray, shape (m,)
        Frequencies, Hz.
    tc : ndarray, shape (k,)
        Centre times of the segments, s.
    amplitude : ndarray, shape (m, k)
        Amplitude spectrum of each segment (Hann window), unit of ``y``.
    """
    from scipy.signal import spectrogram as _spectrogram

    dt, u, per = _segments(t, y, segment, samples)
    t0 = float(np.asarray(t, float)[0])
    f, tc, s = _spectrogram(u, fs=1.0 / dt, window="hann", nperseg=per, noverlap=per // 2,
                            scaling="spectrum", mode="magnitude", detrend="constant")
    return f, t0 + tc, 2.0 * s


def order_spectrum(angle, y, *, period: float = 2.0 * np.pi, orders: int = 20):
    """Harmonics of a signal of a cyclic run against its cycle angle: the amplitude of
    each order (multiple of the turn), whatever the speed fluctuation.

    Parameters
    ----------
    angle : array_like, shape (n,)
        The cycle angle (a crank's), rad, monotonic (it is unwrapped).
    y : array_like, shape (n,)
        The signal, in its unit.
    period : float
        Angle of one cycle, rad.
    orders : int
        Orders returned (0 .. orders).

    Returns
    -------
    pandas.DataFrame
        ``order`` and ``amplitude`` (unit of ``y``; the mean at order 0), from the whole
        cycles covered, resampled uniformly in angle.

    Raises
    ------
    ValueError
        The angle is not monotonic or covers less than one cycle.
    """
    import pandas as pd
    from scipy.interpolate import CubicSpline

    a, y = np.unwrap(np.asarray(angle, float)), np.asarray(y, float)
    if a[-1] < a[0]:
        a, y = -a[::-1], y[::-1]
    keep = np.concatenate([[True], np.diff(a) > 0])
    a, y = a[keep], y[keep]
    cycles = int(np.floor((a[-1] - a[0]) / period + 1e-9))
    if cycles < 1 or a.size < 8:
        raise ValueError("an order spectrum needs a monotonic angle over at least one cycle")
    per = max(64, 4 * (orders + 1))
    grid = a[0] + np.arange(cycles * per) * (period / per)
    c = np.fft.rfft(CubicSpline(a, y)(grid)) / grid.size
    amp = 2.0 * np.abs(c[::cycles][:orders + 1])
    amp[0] /= 2.0
    return pd.DataFrame({"order": np.arange(amp.size), "amplitude": amp})


def welch(t, y, *, segment: float | None = None, samples: int | None = None):
    """Power spectral density by Welch's method (:func:`scipy.signal.welch`, Hann window,
    half-overlapping segments): for a noisy or long transient history.

    Parameters
    ----------
    t, y : array_like, shape (n,)
        As in :func:`spectrum`.
    segment : float, optional
        Length of each segment, s (default 1/8 of the run).

    Returns
    -------
    pandas.DataFrame
        ``f_Hz`` and ``psd`` (unit of ``y`` squared per Hz).
    """
    import pandas as pd
    from scipy.signal import welch as _welch

    dt, u, per = _segments(t, y, segment, samples)
    f, p = _welch(u, fs=1.0 / dt, window="hann", nperseg=min(per, u.size))
    return pd.DataFrame({"f_Hz": f, "psd": p})


def summary(t, y, n: int = 5) -> dict:
    """Peak, RMS and the dominant components of a history, for a table.

    Returns
    -------
    dict
        ``peak`` (largest absolute value) and ``peak_t`` (its time, s), ``rms``, ``mean``
        (time averages over the run, trapezoidal in t) and ``dominant`` (the DataFrame of
        :func:`dominant`).
    """
    t, y = np.asarray(t, float), np.asarray(y, float)
    k = int(np.argmax(np.abs(y)))
    span = t[-1] - t[0]
    return {"peak": float(y[k]), "peak_t": float(t[k]),
            "rms": float(np.sqrt(np.trapezoid(y * y, t) / span)),
            "mean": float(np.trapezoid(y, t) / span), "dominant": dominant(t, y, n)}


def history(record, column: str):
    """The times, s, and the values of a column of a record's table
    (``record.to_dataframe()``, e.g. ``"Fy_frame_N"`` of a trajectory): (t, y).

    Raises
    ------
    KeyError
        An unknown column (the message lists the valid ones).
    """
    df = record.to_dataframe()
    if column not in df:
        raise KeyError(f"no column {column!r}; valid columns: {', '.join(df.columns)}")
    return df["t_s"].to_numpy(), df[column].to_numpy(dtype=float)


def of_column(record, column: str, how=spectrum, **options):
    """Apply :func:`spectrum`, :func:`dominant`, :func:`spectrogram`, :func:`welch` or
    :func:`summary` to a column of a record's table (see :func:`history`).

    Raises
    ------
    KeyError
        An unknown column (the message lists the valid ones).
    """
    return how(*history(record, column), **options)
