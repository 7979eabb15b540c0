"""The figures of the plots: panels on matplotlib's Agg canvas, written atomically.

Nothing here needs a screen or changes pyplot's backend.  Every ``plot_*`` function saves
its figure with :func:`save`; given ``path=None`` it returns the
:class:`matplotlib.figure.Figure` instead (to inspect it, or to save it yourself).
"""

from __future__ import annotations

from .table import output_path, written

__all__ = ["figure", "mosaic", "save"]


def _new(width: float, height: float):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def figure(n_rows: int, width: float = 8.0, height: float = 2.6, sharex: bool = True):
    """A figure on the Agg canvas with ``n_rows`` gridded panels (sharing x unless
    ``sharex`` is False): (fig, axes)."""
    fig = _new(width, height * n_rows)
    axes = fig.subplots(n_rows, 1, sharex=sharex, squeeze=False)[:, 0]
    for ax in axes:
        ax.grid(True, alpha=0.3)
    return fig, axes


def mosaic(layout, width: float, height: float, **kwargs):
    """A figure on the Agg canvas with gridded panels named by ``layout`` (as matplotlib's
    ``subplot_mosaic``; ``kwargs`` passed on): (fig, dict of axes)."""
    fig = _new(width, height)
    axes = fig.subplot_mosaic(layout, **kwargs)
    for ax in axes.values():
        ax.grid(True, alpha=0.3)
    return fig, axes


def save(fig, path, dpi):
    """Write ``fig`` to ``path`` (its type from the suffix), atomically; returns the path
    (``path`` None: returns ``fig``, unsaved)."""
    if path is None:
        return fig
    path = output_path(path)
    with written(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    return path
