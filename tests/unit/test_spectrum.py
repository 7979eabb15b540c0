"""Spectra of histories sampled at any times (issue 11: spectra of any history)."""

import numpy as np
import pytest

import mechdyn as md
from mechdyn.results import spectrum as S


def _two_tones(seed=3):
    t = np.sort(np.random.default_rng(seed).uniform(0.0, 12.0, 5000))  # non-uniform
    y = 1.7 + 2.0 * np.sin(2 * np.pi * 4.7 * t) + 0.35 * np.cos(2 * np.pi * 31.3 * t + 0.4)
    return t, y


def test_two_tones_sampled_non_uniformly_are_recovered_to_1e_3():
    t, y = _two_tones()
    d = S.dominant(t, y, 2)
    np.testing.assert_allclose(d["f_Hz"], [4.7, 31.3], rtol=1e-3)
    np.testing.assert_allclose(d["amplitude"], [2.0, 0.35], rtol=1e-3)
    sp = S.spectrum(t, y)  # flat-top window: the amplitude at the nearest bin
    near = sp.iloc[(sp["f_Hz"] - 4.7).abs().idxmin()]
    assert near["amplitude"] == pytest.approx(2.0, rel=3e-3)
    assert sp["amplitude"].iloc[0] == pytest.approx(1.7, rel=1e-2)  # the mean over the run


def test_a_spectrogram_shows_a_tone_that_starts_halfway():
    t = np.linspace(0.0, 8.0, 8001)
    y = np.where(t > 4.0, np.sin(2 * np.pi * 10.0 * t), 0.0)
    f, tc, a = S.spectrogram(t, y, segment=1.0)
    k = np.argmin(np.abs(f - 10.0))
    assert a[k, tc < 3.5].max() < 0.01 and a[k, tc > 4.5].min() > 0.5


def test_spectrum_of_a_column_of_a_run():
    tr = md.simulate(md.examples.load("four_bar"), 1.0, t_eval=np.linspace(0, 1, 2001),
                     progress=False)
    sp = S.of_column(tr, "Fy_frame_N")
    assert {"f_Hz", "amplitude"} <= set(sp.columns) and np.all(np.isfinite(sp["amplitude"]))
    with pytest.raises(KeyError, match="valid columns"):
        S.of_column(tr, "Fz_frame_N")


def test_orders_of_a_cyclic_run_whatever_the_speed():
    """A second-order load of a crank whose speed fluctuates by 30 %: its order spectrum
    has the amplitude at order 2 and nothing at the other orders."""
    t = np.linspace(0.0, 2.0, 3001)
    phi = 2 * np.pi * 3.0 * t + 0.3 * np.sin(2 * np.pi * 3.0 * t)  # 6 turns, uneven
    y = 0.5 + 4.0 * np.cos(2 * phi + 0.2)
    o = S.order_spectrum(phi, y, orders=5)
    np.testing.assert_allclose(o["amplitude"], [0.5, 0, 4.0, 0, 0, 0], atol=1e-6)


def test_psd_and_summary_of_a_sinusoid():
    t = np.linspace(0.0, 20.0, 20001)
    y = 3.0 * np.sin(2 * np.pi * 5.0 * t)
    p = S.welch(t, y, segment=4.0)
    assert p["f_Hz"].iloc[p["psd"].idxmax()] == pytest.approx(5.0, abs=0.25)
    # Parseval: the PSD integrates to the mean square, A^2 / 2
    assert np.trapezoid(p["psd"], p["f_Hz"]) == pytest.approx(4.5, rel=2e-2)
    s = S.summary(t, y, n=1)
    assert s["rms"] == pytest.approx(3.0 / np.sqrt(2.0), rel=1e-6)
    assert abs(s["peak"]) == pytest.approx(3.0, rel=1e-6) and abs(s["mean"]) < 1e-6
    assert s["dominant"]["f_Hz"].iloc[0] == pytest.approx(5.0, rel=1e-9)
