"""``mechdyn.results.plot.plot`` draws every kind of record it lists."""

import mechdyn
from mechdyn.reduction.reduce import reduce_model
from mechdyn.results.plot import PLOTTERS, plot, plot_trajectory  # noqa: F401


def test_plot_dispatches_every_record_kind(tmp_path):
    model = mechdyn.examples.load("slider_crank").compile()
    records = [mechdyn.simulate(model, 0.05, progress=False),
               mechdyn.kinetostatics(model, speed=10.0),
               mechdyn.kinematics.sweep.sweep(model),
               reduce_model(model, steps=73)]
    for rec in records:
        out = plot(rec, tmp_path / f"{type(rec).__name__}.png")
        assert out.stat().st_size > 1000, type(rec).__name__
    assert {type(r).__name__ for r in records} <= set(PLOTTERS)


def test_plot_of_a_history_its_spectrum_and_spectrogram(tmp_path):
    import numpy as np
    import pytest

    from mechdyn.results.plot import plot_spectrum

    tr = mechdyn.simulate(mechdyn.examples.load("four_bar"), 1.0,
                          t_eval=np.linspace(0.0, 1.0, 2001), progress=False)
    out = plot_spectrum(tr, "Fy_frame_N", tmp_path / "spectrum.png", f_max=30.0)
    assert out.stat().st_size > 1000
    with pytest.raises(KeyError, match="valid columns"):
        plot_spectrum(tr, "F_nowhere_N", tmp_path / "x.png")
