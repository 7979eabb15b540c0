"""Animations and still frames of a mechanism's motion (GIF, MP4, PNG).

:func:`animate` draws every frame of a record that carries body poses ``x``
(shape (n, n_x)) and its compiled ``model`` -- a
:class:`~mechdyn.kinematics.records.KinematicSweep`, a
:class:`~mechdyn.results.trajectory.Trajectory` or a
:class:`~mechdyn.results.kinetostatics_record.Kinetostatics` -- and writes a GIF
(with Pillow, as matplotlib's ``PillowWriter`` does) or an MP4 (only when ffmpeg is installed).
:func:`snapshot` writes one frame as a PNG.

What each frame shows (bodies through their points, joints, ground anchors, slider
guides, an optional traced point, the time or swept value in the corner) is listed in
``docs/results.md``; :func:`frame_geometry` gives its coordinates, which the tests compare
with :func:`mechdyn.model.constraints.point_position`.  The axis limits are fixed
from the whole motion and the aspect ratio is equal.  Figures are drawn on matplotlib's
Agg canvas; pyplot is not used.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import MechdynError, ModelError
from .figure import figure, save
from .frame_geometry import (
    MechanismDrawing,
    _labels,
    _record_parts,
    _zigzag,
    frame_geometry,
    frame_indices,
    trace_spec,
)
from .table import output_path, written

__all__ = ["animate", "snapshot", "frame_geometry", "frame_indices", "check_animation_path",
           "MechanismDrawing"]

#: width of a frame, inches (at the default dpi 100: 900 pixels)
FRAME_WIDTH = 9.0


class _Scene:
    """The matplotlib artists of one figure, updated frame by frame."""

    def __init__(self, record, *, trace=None, title=None, width: float = FRAME_WIDTH,
                 labels: bool = True):
        from matplotlib.lines import Line2D
        from matplotlib.patches import FancyArrowPatch, Polygon

        model, _ = _record_parts(record)
        self.trace = trace_spec(model, trace)
        self.g = g = frame_geometry(record, trace=self.trace)  # every frame, drawn by update()
        (x0, x1), (y0, y1) = g["limits"]
        # the figure's shape follows the drawing's (room for title and labels added)
        height = float(np.clip((width - 1.0) * (y1 - y0) / (x1 - x0) + 1.2, 4.5, 10.0))
        self.fig, (ax,) = figure(1, width, height)
        self.ax = ax
        from matplotlib.ticker import FuncFormatter

        mm = FuncFormatter(lambda v, _: f"{v * 1e3:.6g}")  # the drawing in m, the axes in mm
        ax.xaxis.set_major_formatter(mm)
        ax.yaxis.set_major_formatter(mm)
        ax.set(xlim=(x0, x1), ylim=(y0, y1), xlabel="x (mm)", ylabel="y (mm)",
               title=title if title is not None else getattr(model.mechanism, "name", "mechanism"))
        ax.set_aspect("equal", adjustable="box")
        s = g["size"]
        # static: anchors (hatched triangles) and ground guides
        for p in g["anchors"].values():
            tri = np.array([p, p + [-1.2 * s, -1.8 * s], p + [1.2 * s, -1.8 * s]])
            ax.add_patch(Polygon(tri, closed=True, facecolor="0.85", edgecolor="0.3",
                                 hatch="////", lw=1.0, zorder=1))
            ax.plot([p[0] - 1.8 * s, p[0] + 1.8 * s], [p[1] - 1.8 * s] * 2, color="0.3",
                    lw=1.5, zorder=1)
        # the moving artists start empty: update() places them
        self.guides = {j: ax.plot([], [], color="0.35", lw=2.5, alpha=0.6,
                                  solid_capstyle="butt", zorder=1)[0] for j in g["guides"]}
        if self.trace is not None:
            gt = g["trace"]
            ax.plot(gt[:, 0], gt[:, 1], color="tab:red", lw=0.8, ls=":", alpha=0.6, zorder=2)
            (self.trace_line,) = ax.plot([], [], color="tab:red", lw=1.4, zorder=2,
                                         label=f"path of {self.trace[0]}.{self.trace[1]}")
            (self.trace_dot,) = ax.plot([], [], "o", color="tab:red", ms=4, zorder=6)
            ax.legend(loc="upper right", fontsize="small")
        # moving bodies
        self.bodies = {}
        for k, (b, style) in enumerate(g["styles"].items()):
            c = f"C{k}"  # the colour cycle
            if style in ("polygon", "block"):
                art = Polygon(g["bodies"][b][0], closed=True, facecolor=c, alpha=0.45,
                              edgecolor=c, lw=2.0, zorder=3, label=b)
                ax.add_patch(art)
            elif style == "bar":
                (art,) = ax.plot([], [], color=c, lw=5.0, alpha=0.8, solid_capstyle="round",
                                 zorder=3, label=b)
            else:
                (art,) = ax.plot([], [], "o", color=c, ms=9, zorder=3, label=b)
            self.bodies[b] = (art, style)
        (self.revolutes,) = ax.plot([], [], "o", ms=7, mfc="white", mec="black", mew=1.3,
                                    zorder=5, ls="none")
        (self.locks,) = ax.plot([], [], "s", ms=7, mfc="0.2", mec="black", zorder=5, ls="none")
        # springs (zigzags), stops (dark red bars), loads (green arrows), joint forces (red)
        self.springs = {n: ax.plot([], [], color="tab:brown", lw=1.4, zorder=4)[0]
                        for n in g["springs"]}
        self.stops = {n: ax.plot([], [], color="darkred", lw=3.5, solid_capstyle="butt",
                                 zorder=4)[0] for n in g["stops"]}
        arrow = {"arrowstyle": "-|>", "mutation_scale": 14, "zorder": 6}
        self.loads = {n: ax.add_patch(FancyArrowPatch((0, 0), (0, 0), color="tab:green",
                                                      lw=2.0, **arrow)) for n in g["loads"]}
        self.reactions = {n: ax.add_patch(FancyArrowPatch((0, 0), (0, 0), color="tab:red",
                                                          lw=1.6, **arrow))
                          for n in g["reactions"]}
        # the names: bodies at their outline's centre, joints beside the pin, loads at the tip
        self.labels = {}
        if labels:
            font = {"fontsize": "small", "zorder": 8, "clip_on": True}
            for b in g["bodies"]:
                self.labels[("bodies", b)] = ax.text(0, 0, b, ha="center", va="center",
                                                     color="0.1", fontweight="bold", **font)
            for kind in ("revolutes", "locks"):
                for j in g[kind]:
                    self.labels[(kind, j)] = ax.text(0, 0, j, ha="left", va="bottom",
                                                     color="0.25", **font)
            for n in g["loads"]:
                self.labels[("loads", n)] = ax.text(0, 0, n, ha="left", va="bottom",
                                                    color="tab:green", **font)
        keys = [("spring", "tab:brown", "-", g["springs"]), ("stop", "darkred", "-", g["stops"]),
                ("load", "tab:green", "-", g["loads"]),
                ("joint force", "tab:red", "-", g["reactions"])]
        handles = [Line2D([], [], color=c, ls=ls, lw=2.0, label=lab)
                   for lab, c, ls, items in keys if items]
        if handles or self.trace is not None:
            old_legend = ax.get_legend()
            ax.legend(handles=(old_legend.legend_handles if old_legend else []) + handles,
                      loc="upper right", fontsize="small")
        if g["reactions"]:
            ax.text(0.98, 0.02, f"joint forces: 1 mm = {1e-3 / g['force_scale']:.4g} N",
                    transform=ax.transAxes, ha="right", va="bottom", fontsize="small",
                    color="tab:red")
        self.text = ax.text(0.02, 0.97, "", transform=ax.transAxes, ha="left", va="top",
                            family="monospace", fontsize="medium",
                            bbox={"boxstyle": "round", "fc": "white", "ec": "0.7",
                                  "alpha": 0.85}, zorder=7)

    def render(self, idx, labels, dpi: int):
        """Yield one RGB :class:`PIL.Image.Image` per sample of ``idx`` (blitting)."""
        from PIL import Image

        canvas = self.fig.canvas
        self.fig.set_dpi(dpi)
        moving = [a for a, _ in self.bodies.values()] + list(self.guides.values())
        moving += [self.revolutes, self.locks, self.text, *self.springs.values(),
                   *self.stops.values(), *self.loads.values(), *self.reactions.values(),
                   *self.labels.values()]
        if self.trace is not None:
            moving += [self.trace_line, self.trace_dot]
        for a in moving:
            a.set_animated(True)
        canvas.draw()  # the background: axes, anchors, the faint trace
        self.fig.set_layout_engine("none")
        background = canvas.copy_from_bbox(self.fig.bbox)
        for i, lab in zip(idx, labels, strict=True):
            canvas.restore_region(background)
            self.update(int(i), lab)
            for a in moving:
                self.ax.draw_artist(a)
            buf = np.asarray(canvas.buffer_rgba())
            yield Image.fromarray(buf[..., :3].copy(), mode="RGB")
        for a in moving:
            a.set_animated(False)

    def update(self, i: int, label: str) -> None:
        """Move every artist to sample ``i``."""
        g = self.g
        for b, (art, style) in self.bodies.items():
            P = g["bodies"][b][i]
            if style in ("polygon", "block"):
                art.set_xy(P)
            else:
                art.set_data(P[:, 0], P[:, 1])
        for kind in ("revolutes", "locks"):
            P = np.array([v[i] for v in g[kind].values()]).reshape(-1, 2)
            getattr(self, kind).set_data(P[:, 0], P[:, 1])
        for j, ln in self.guides.items():
            seg = g["guides"][j][i]
            ln.set_data(seg[:, 0], seg[:, 1])
        for n, ln in self.springs.items():
            ln.set_data(*_zigzag(*g["springs"][n][i], g["size"]).T)
        for n, ln in self.stops.items():
            ln.set_data(*g["stops"][n][i].T)
        for kind in ("loads", "reactions"):
            for n, art in getattr(self, kind).items():
                art.set_positions(*g[kind][n][i])
        s = g["size"]
        for (kind, n), txt in self.labels.items():
            if kind == "bodies":
                txt.set_position(np.mean(g["bodies"][n][i], axis=0))
            elif kind == "loads":
                txt.set_position(g["loads"][n][i, 1])
            else:
                txt.set_position(g[kind][n][i] + 0.6 * s)
        if self.trace is not None:
            path = g["trace"]
            self.trace_line.set_data(path[: i + 1, 0], path[: i + 1, 1])
            self.trace_dot.set_data([path[i, 0]], [path[i, 1]])
        self.text.set_text(label)


def animate(record, path, *, fps: int = 25, frames: int | None = None, trace=None,
            title: str | None = None, dpi: int = 100, labels: bool = True) -> Path:
    """Write an animation of a mechanism's motion (GIF, or MP4 when ffmpeg exists).

    Parameters
    ----------
    record : KinematicSweep, Trajectory or Kinetostatics
        Anything with body poses ``x`` (n, n_x) and its compiled ``model``.
    path : str or Path
        Output file; ``.gif`` (always available) or ``.mp4`` (needs ffmpeg).
    fps : int
        Frames per second of the animation.
    frames : int, optional
        Number of frames drawn, subsampled from the record (default
        ``min(n, 200)``; a trajectory is subsampled equally in time).
    trace : "BODY.POINT" or (body, point), optional
        Draw the path of this point.
    title : str, optional
        Title above the drawing (default the mechanism's name).
    dpi : int
        Resolution of the frames (the figure is 9 inches wide: 900 pixels at 100 dpi).
    labels : bool
        Name the bodies, joints and loads on the drawing.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    MechdynError
        Unsupported file type, or ``.mp4`` without ffmpeg (use ``.gif``).
    ModelError
        A record without poses or model, or an unknown trace point.
    """
    from matplotlib import animation
    from PIL import Image

    path = check_animation_path(path)
    if fps <= 0:
        raise ModelError(f"fps must be positive, got {fps}")
    idx = frame_indices(record, frames)
    labels = _labels(record, idx)
    scene = _Scene(record, trace=trace, title=title, labels=labels)
    path = output_path(path)
    if path.suffix.lower() == ".mp4":  # pragma: no cover - needs ffmpeg
        writer = animation.FFMpegWriter(fps=fps)
        with writer.saving(scene.fig, str(path), dpi):
            for i, lab in zip(idx, labels, strict=True):
                scene.update(int(i), lab)
                writer.grab_frame()
        return path
    images = list(scene.render(idx, labels, dpi))
    # one shared palette, taken from the first, middle and last frames
    w, h = images[0].size
    probe_ids = sorted({0, len(images) // 2, len(images) - 1})
    probe = Image.new("RGB", (w, h * len(probe_ids)))
    for j, k in enumerate(probe_ids):
        probe.paste(images[k], (0, j * h))
    palette = probe.quantize(colors=128, method=Image.Quantize.MEDIANCUT,
                             dither=Image.Dither.NONE)
    images = [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]
    # as matplotlib's PillowWriter does, but with the background drawn once and one palette
    with written(path) as tmp:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                       duration=max(1, round(1000 / fps)), loop=0)
    return path


def check_animation_path(path) -> Path:
    """The output path of :func:`animate` if its format can be written, else a clear error.

    Raises
    ------
    MechdynError
        Neither ``.gif`` nor ``.mp4``, or ``.mp4`` without ffmpeg.
    """
    from matplotlib import animation

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise MechdynError(f"cannot write {str(path)!r}: animations are written as .gif "
                           "(or .mp4 when ffmpeg is installed)")
    if suffix == ".mp4" and not animation.FFMpegWriter.isAvailable():
        raise MechdynError(f"cannot write {str(path)!r}: MP4 needs ffmpeg, which is not "
                           "installed; write a .gif instead (e.g. -o motion.gif)")
    return path


def snapshot(record, path, index: int = 0, *, trace=None, title: str | None = None,
             dpi: int = 110, labels: bool = True):
    """Write one frame of the motion as an image (PNG, or any matplotlib format).

    Parameters
    ----------
    record : KinematicSweep, Trajectory or Kinetostatics
    path : str or Path or None
        Image file (format from the suffix, e.g. ``.png``, ``.svg``); a binary
        file object is also accepted (PNG); None returns the figure.
    index : int
        Sample to draw (negative counts from the end).
    trace : "BODY.POINT" or (body, point), optional
        Draw the path of this point (up to this sample, and faint for all of it).
    title : str, optional
    dpi : int
    labels : bool
        Name the bodies, joints and loads on the drawing.

    Returns
    -------
    Path or the file object, or the Figure when ``path`` is None
    """
    model, x = _record_parts(record)
    n = x.shape[0]
    if not -n <= index < n:
        raise ModelError(f"index {index} is outside the record's {n} samples")
    i = int(index) % n
    scene = _Scene(record, trace=trace, title=title, labels=labels)
    scene.update(i, _labels(record, np.array([i]))[0])
    if path is None:
        return scene.fig
    if hasattr(path, "write"):
        scene.fig.savefig(path, dpi=dpi, format="png")
        return path
    return save(scene.fig, path, dpi)
