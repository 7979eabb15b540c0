"""The interactive figures of a report (plotly): one per section, in engineering units.

* :func:`sweep_figure` -- link angles (deg), angular velocities and accelerations, and the
  positions (mm), velocities and accelerations of points against the swept coordinate;
* :func:`kinetostatics_figure` -- driving torque (N m) and joint forces (kN) on separate
  axes; with friction the power lost per pair (W) and the efficiency (%);
* :func:`trajectory_figure` -- coordinates (deg, mm), speeds (rpm, m/s) and the frame force
  (kN) against time, switching events as vertical lines and modes shaded;
* :func:`frame_load_figure`, :func:`spectrum_figure`, :func:`supports_figure` -- the loads
  on the building.

Every trace is decimated to at most ``max_points`` points (keeping each bucket's minimum
and maximum, so peaks survive) to keep the page small.
"""

from __future__ import annotations

import numpy as np

from .table import deg_or_mm

__all__ = ["decimate", "Figure", "sweep_figure", "kinetostatics_figure", "trajectory_figure",
           "frame_load_figure", "spectrum_figure", "supports_figure", "frame_floor_figure",
           "MAX_POINTS"]

#: points per trace at most
MAX_POINTS = 2000

#: the frame-load series keep their colour from figure to figure
_FIXED = {"Fx": "#1f77b4", "Fy": "#ff7f0e", "|F|": "#2ca02c", "M": "#d62728"}

_MODE_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                "#7f7f7f", "#bcbd22", "#17becf")


def decimate(x, y, max_points: int = MAX_POINTS):
    """(x, y) reduced to at most about ``max_points`` points: in each of ``max_points / 2``
    buckets the samples of the smallest and the largest y, in order (NaN gaps kept).

    Examples
    --------
    >>> x = np.arange(10_000.0)
    >>> xs, ys = decimate(x, np.sin(x / 500), 200)
    >>> len(xs) <= 200, float(ys.max()) == float(np.sin(x / 500).max())
    (True, True)
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    n = x.size
    if n <= max_points:
        return x, y
    edges = np.linspace(0, n, max_points // 2 + 1).astype(int)
    keep = [0, n - 1]
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        seg = y[a:b]
        if seg.size == 0:
            continue
        ok = np.isfinite(seg)
        if not ok.any():
            keep.append(a)
            continue
        if not ok.all():
            keep.append(a + int(np.flatnonzero(~ok)[0]))  # keep a gap a gap
        keep += [a + int(np.nanargmin(seg)), a + int(np.nanargmax(seg))]
    idx = np.unique(keep)
    return x[idx], y[idx]


class Figure:
    """A plotly figure of stacked panels sharing the x axis, which tracks the y range of each
    panel (for the event lines) and decimates every trace."""

    def __init__(self, titles, ylabels, xlabel: str, *, cols: int = 1, title: str = "",
                 row_height: int = 230, max_points: int = MAX_POINTS):
        from plotly.subplots import make_subplots

        self.rows = -(-len(titles) // cols)
        self.cols = cols
        self.max_points = max_points
        self.fig = make_subplots(rows=self.rows, cols=cols, shared_xaxes=True,
                                 subplot_titles=list(titles),
                                 vertical_spacing=min(0.3 / self.rows, 0.12),
                                 horizontal_spacing=0.09)
        self.ylabels = list(ylabels)
        self.xlabel = xlabel
        self.title = title
        self.row_height = row_height
        self.extent: dict = {}
        self._colors: dict = {}

    def _cell(self, panel: int) -> tuple[int, int]:
        return panel // self.cols + 1, panel % self.cols + 1

    def line(self, panel: int, x, y, name: str, unit: str, *, group: str | None = None,
             dash: str | None = None, mode: str = "lines") -> None:
        """Add a trace to panel ``panel`` (0-based, row-major), its values in ``unit``."""
        import plotly.graph_objects as go

        y = np.asarray(y, float)
        if y.size == 0 or not np.isfinite(y).any():
            return
        x, y = decimate(x, y, self.max_points)
        row, col = self._cell(panel)
        group = group or name
        color = self._colors.setdefault(group, _FIXED.get(group)
                                        or _MODE_COLORS[len(self._colors) % 10])
        first = sum(1 for tr in self.fig.data if tr.legendgroup == group) == 0
        self.fig.add_trace(go.Scatter(
            x=x, y=y, name=name, mode=mode, legendgroup=group, showlegend=first,
            line={"color": color, "dash": dash, "width": 1.6},
            hovertemplate=f"{name}: %{{y:.4g}} {unit}<extra></extra>"), row=row, col=col)
        lo, hi = float(np.nanmin(y)), float(np.nanmax(y))
        old = self.extent.get(panel)
        self.extent[panel] = (lo, hi) if old is None else (min(old[0], lo), max(old[1], hi))

    def bars(self, panel: int, x, y, name: str, unit: str) -> None:
        """Add a bar trace (amplitudes per order) to a panel."""
        import plotly.graph_objects as go

        row, col = self._cell(panel)
        color = self._colors.setdefault(name, _FIXED.get(name)
                                        or _MODE_COLORS[len(self._colors) % 10])
        first = sum(1 for tr in self.fig.data if tr.legendgroup == name) == 0
        self.fig.add_trace(go.Bar(x=np.asarray(x, float), y=np.asarray(y, float), name=name,
                                  legendgroup=name, showlegend=first, marker_color=color,
                                  hovertemplate=f"{name}: %{{y:.4g}} {unit}<extra></extra>"),
                           row=row, col=col)

    def events(self, times, labels, *, name: str = "switching events", limit: int = 300
               ) -> int:
        """Vertical lines at ``times`` through every panel (hover: the label); at most
        ``limit`` (the first ones).  Returns how many were drawn."""
        import plotly.graph_objects as go

        times = list(times)[:limit]
        if not times:
            return 0
        for panel, (lo, hi) in self.extent.items():
            pad = 0.05 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.05
            lo, hi = lo - pad, hi + pad
            xs, ys, texts = [], [], []
            for t, label in zip(times, labels, strict=False):
                xs += [t, t, None]
                ys += [lo, hi, None]
                texts += [label, label, None]
            row, col = self._cell(panel)
            self.fig.add_trace(go.Scatter(
                x=xs, y=ys, mode="lines", name=name, legendgroup="events",
                showlegend=panel == min(self.extent), hovertext=texts, hoverinfo="text+x",
                line={"color": "rgba(90,90,90,0.75)", "width": 1, "dash": "dot"}),
                row=row, col=col)
            self.fig.update_yaxes(range=[lo, hi], row=row, col=col)
        return len(times)

    def shade(self, spans) -> None:
        """Shade the intervals ``(x0, x1, label)`` of constant mode, one colour and one
        legend entry per mode."""
        if not spans:
            return
        colors: dict = {}
        shapes = []
        for x0, x1, label in spans:
            first = label not in colors
            color = colors.setdefault(label, _MODE_COLORS[(len(colors) + 5) % 10])
            shapes.append({"type": "rect", "xref": "x", "yref": "paper", "x0": x0, "x1": x1,
                           "y0": 0, "y1": 1, "fillcolor": color, "opacity": 0.12,
                           "layer": "below", "line": {"width": 0}, "name": f"mode {label}",
                           "legendgroup": f"mode {label}", "showlegend": first})
        self.fig.update_layout(shapes=list(self.fig.layout.shapes) + shapes)  # at once: fast

    def done(self, *, x_range=None):
        """The plotly figure, axes labelled."""
        fig = self.fig
        for panel, label in enumerate(self.ylabels):
            row, col = self._cell(panel)
            fig.update_yaxes(title_text=label, row=row, col=col, zeroline=True,
                             zerolinecolor="#bbb")
        for col in range(1, self.cols + 1):
            fig.update_xaxes(title_text=self.xlabel, row=self.rows, col=col)
        if x_range is not None:
            fig.update_xaxes(range=list(x_range))
        fig.update_layout(title={"text": self.title, "x": 0.0, "xanchor": "left"},
                          height=90 + self.row_height * self.rows, template="plotly_white",
                          hovermode="x unified", margin={"l": 70, "r": 20, "t": 70, "b": 50},
                          legend={"orientation": "h", "yref": "container", "y": 0.0,
                                  "yanchor": "bottom", "x": 0.0, "groupclick": "togglegroup"})
        return fig


# ---------------------------------------------------------------- helpers
def _point_label(body, name) -> str:
    return f"{body}.{name}" if isinstance(name, str) else \
        f"{body}({name[0] * 1e3:.4g}, {name[1] * 1e3:.4g} mm)"


def default_points(model, trace=None) -> list:
    """The points a kinematics figure shows: the guided point of every slider (else the named
    points of the last body) and the traced point."""
    mech = model.mechanism
    pts = []
    for jn in model.pri.names:
        j = mech.joints[jn]
        if j.child != "ground":
            pts.append((j.child, j.child_point, f"{j.child} on {jn}"))
    if not pts:
        body = model.body_names[-1]
        pts = [(body, p, _point_label(body, p)) for p in list(mech.bodies[body].points)
               or ["com"]]
    if trace is not None:
        from .frame_geometry import trace_spec

        body, name = trace_spec(model, trace)
        if not any(b == body and isinstance(n, str) and n == name for b, n, _ in pts):
            pts.append((body, name, _point_label(body, name)))
    return pts


# ---------------------------------------------------------------- sections
def sweep_figure(sw, *, trace=None, title: str = ""):
    """Kinematics against the swept coordinate: link angles (deg), angular velocities (rad/s)
    and accelerations (rad/s²) on the left; point positions (mm), velocities (m/s) and
    accelerations (m/s²) on the right (a side without anything that moves is left out)."""
    model = sw.model
    xs, xunit = deg_or_mm(np.asarray(sw.values, float), sw.over_is_angle)
    bodies = [(b, *sw.angular(b)) for b in model.body_names]
    bodies = [row for row in bodies if np.ptp(row[1]) > 1e-12]  # translating bodies aside
    scale = model.length_scale
    points = []
    for body, name, label in default_points(model, trace):
        r, v, a = sw.point(body, name)
        points += [(f"{comp} {label}", r[:, c], v[:, c], a[:, c]) for c, comp in enumerate("xy")
                   if np.ptp(r[:, c]) > 1e-12 * scale]  # a constant component aside
    sides = []
    if bodies:
        sides.append((["link angles", "angular velocities", "angular accelerations"],
                      ["angle (deg)", "ω (rad/s)", "α (rad/s²)"]))
    if points or not bodies:
        sides.append((["point positions", "point velocities", "point accelerations"],
                      ["position (mm)", "velocity (m/s)", "acceleration (m/s²)"]))
    cols = len(sides)
    titles = [side[0][r] for r in range(3) for side in sides]
    labels = [side[1][r] for r in range(3) for side in sides]
    f = Figure(titles, labels, f"{sw.over} ({xunit})", cols=cols, title=title)
    if bodies:
        for b, th, om, al in bodies:
            f.line(0, xs, np.rad2deg(th), f"θ {b}", "deg", group=b)
            f.line(cols, xs, om, f"ω {b}", "rad/s", group=b)
            f.line(2 * cols, xs, al, f"α {b}", "rad/s²", group=b)
    c0 = cols - 1
    for g, r, v, a in points:
        f.line(c0, xs, r * 1e3, g, "mm", group=g)
        f.line(c0 + cols, xs, v, f"v{g}", "m/s", group=g)
        f.line(c0 + 2 * cols, xs, a, f"a{g}", "m/s²", group=g)
    return f.done(x_range=(xs[0], xs[-1]) if xs.size > 1 else None)


def kinetostatics_figure(ks, *, title: str = ""):
    """Driving torque (N m; a travel's driving force in kN) and joint forces (kN) against the
    driven coordinate, on separate axes; with friction in the pairs also the power lost in
    each pair and in all (W) and the instantaneous efficiency (%, with the cycle efficiency
    as a dashed level; the axis kept to -100..200 % where the ratio runs off, near zero
    input power)."""
    xs, xunit = deg_or_mm(np.asarray(ks.values, float), ks.over_is_angle)
    torque = [c for c in ks.driven if ks._drive_unit(c)[1] == "Nm"]
    force = [c for c in ks.driven if c not in torque]
    titles, labels = [], []
    if torque:
        titles.append("driving torque")
        labels.append("torque (N m)")
    if force:
        titles.append("driving force")
        labels.append("force (kN)")
    titles.append("joint forces |F|")
    labels.append("force (kN)")
    friction = ks.power_out is not None
    if friction:
        titles += ["power lost by friction", "efficiency"]
        labels += ["power lost (W)", "efficiency (%)"]
    f = Figure(titles, labels, f"{ks.over} ({xunit})", title=title)
    for c in torque:
        f.line(0, xs, ks.driving[c], f"M {c}" + ("" if c == ks.over else " (holding)"), "N m")
    for c in force:
        f.line(int(bool(torque)), xs, np.asarray(ks.driving[c]) / 1e3,
               f"F {c}" + ("" if c == ks.over else " (holding)"), "kN")
    panel = len(titles) - 1 - 2 * friction
    for j in ks.reactions:
        f.line(panel, xs, ks.force_magnitude(j) / 1e3, f"|F| {j}", "kN")
    for el, y in ks.element_forces.items():
        if ks.element_units.get(el, "N") == "N":
            f.line(panel, xs, np.abs(np.asarray(y, float)) / 1e3, f"{el}", "kN")
    if friction:
        _friction_panels(f, ks, xs, panel + 1)
    return f.done(x_range=(xs[0], xs[-1]) if xs.size > 1 else None)


def _friction_panels(f: Figure, ks, xs, panel: int) -> None:
    """The power lost in each pair and in all (W) on ``panel``, the instantaneous and the
    cycle efficiency (%) on the next."""
    for j, p in ks.losses.items():
        f.line(panel, xs, p, f"P lost {j}", "W")
    f.line(panel, xs, ks.power_loss, "P lost, all pairs", "W", dash="dot")
    eta = 100.0 * ks.efficiency
    f.line(panel + 1, xs, eta, "η", "%")
    cycle = 100.0 * ks.cycle_efficiency
    if np.isfinite(cycle):
        f.line(panel + 1, xs, np.full(xs.shape, cycle), f"η cycle {cycle:.3g} %", "%",
               dash="dash")
    ok = eta[np.isfinite(eta)]
    if ok.size and (ok.min() < -100.0 or ok.max() > 200.0):  # near zero input power
        lo, hi = max(float(ok.min()), -100.0), min(float(ok.max()), 200.0)
        pad = 0.05 * (hi - lo)
        row, col = f._cell(panel + 1)
        f.fig.update_yaxes(range=[lo - pad, hi + pad], row=row, col=col)


def trajectory_figure(traj, *, transitions=(), spans=None, title: str = ""):
    """Coordinates (deg, mm), their rates (rpm, m/s) and the frame force (kN) against time,
    events as vertical lines, modes shaded."""
    names = traj.coordinate_names
    is_angle = traj.coordinate_is_angle or (True,) * len(names)
    groups = [("angles", "angle (deg)", [k for k in range(len(names)) if is_angle[k]],
               lambda v: np.rad2deg(v), "deg", "q"),
              ("travels", "travel (mm)", [k for k in range(len(names)) if not is_angle[k]],
               lambda v: v * 1e3, "mm", "q"),
              ("angular speeds", "speed (rpm)", [k for k in range(len(names)) if is_angle[k]],
               lambda v: v * 30 / np.pi, "rpm", "qdot"),
              ("speeds", "speed (m/s)", [k for k in range(len(names)) if not is_angle[k]],
               lambda v: v, "m/s", "qdot")]
    groups = [g for g in groups if g[2]]
    df = traj.to_dataframe(energy=False, bodies=False, degrees=False) if traj.switching \
        else None
    frame = df is not None and "Fx_frame_N" in df
    titles = [g[0] for g in groups] + (["frame force"] if frame else [])
    labels = [g[1] for g in groups] + (["force (kN)"] if frame else [])
    f = Figure(titles, labels, "t (s)", title=title)
    for panel, (_, _, ks, conv, unit, what) in enumerate(groups):
        data = traj.q if what == "q" else traj.qdot
        for k in ks:
            f.line(panel, traj.t, conv(data[:, k]), names[k] if what == "q"
                   else f"{names[k]}'", unit, group=names[k])
    if frame:
        p = len(groups)
        for col, lab in (("Fx_frame_N", "Fx frame"), ("Fy_frame_N", "Fy frame")):
            f.line(p, df["t_s"], df[col].to_numpy(float) / 1e3, lab, "kN")
    f.events([e.t for e in transitions], [e.label for e in transitions])
    f.shade(spans)
    t = np.asarray(traj.t, float)
    return f.done(x_range=(t[0], t[-1]) if t.size > 1 and t[-1] > t[0] else None)


def frame_load_figure(x, xlabel: str, Fx, Fy, M, *, point=(0.0, 0.0), transitions=(),
                      spans=None, title: str = ""):
    """The load on the frame: force Fx, Fy, |F| (kN) and moment (kN m) against ``x``."""
    p = f"({point[0] * 1e3:.4g}, {point[1] * 1e3:.4g}) mm"
    f = Figure(["force on the frame", f"moment on the frame about {p}"],
               ["force (kN)", "moment (kN m)"], xlabel, title=title)
    Fx, Fy = np.asarray(Fx, float), np.asarray(Fy, float)
    f.line(0, x, Fx / 1e3, "Fx", "kN")
    f.line(0, x, Fy / 1e3, "Fy", "kN")
    f.line(0, x, np.hypot(Fx, Fy) / 1e3, "|F|", "kN", dash="dot")
    if M is not None:
        f.line(1, x, np.asarray(M, float) / 1e3, "M", "kN m")
    f.events([e.t for e in transitions], [e.label for e in transitions])
    f.shade(spans)
    x = np.asarray(x, float)
    return f.done(x_range=(x[0], x[-1]) if x.size > 1 and x[-1] != x[0] else None)


def spectrum_figure(series, *, xlabel: str = "f (Hz)", bars: bool = False, title: str = ""):
    """Amplitude spectra: ``series`` a list of (x, amplitude, name, unit) with unit "kN" or
    "kN m" (force and moment in separate panels); ``bars`` for orders."""
    units = [u for u in ("kN", "kN m") if any(s[3] == u for s in series)]
    f = Figure([f"amplitude of the {'force' if u == 'kN' else 'moment'}" for u in units],
               [f"amplitude ({u})" for u in units], xlabel, title=title)
    top = 0.0
    for x, a, name, unit in series:
        if bars:
            f.bars(units.index(unit), x, a, name, unit)
        else:
            f.line(units.index(unit), x, a, name, unit)
            x, e = np.asarray(x, float), np.cumsum(np.asarray(a, float) ** 2)
            if x.size and e[-1] > 0:  # where 99 % of the content lies
                top = max(top, float(x[min(np.searchsorted(e, 0.99 * e[-1]), x.size - 1)]))
    xmax = max((float(np.max(s[0])) for s in series if len(s[0])), default=0.0)
    fig = f.done(x_range=(0.0, min(xmax, 1.5 * top)) if 0.0 < top < xmax / 1.5 else None)
    if bars:
        fig.update_layout(barmode="group", hovermode="x")
    return fig


def supports_figure(x, xlabel: str, loads, *, transitions=(), title: str = ""):
    """Per support: the resultant force it passes to the floor (kN); anchor bolts: tension
    and clamp force (kN)."""
    bolts = [n for n in loads.names if n in loads.tension]
    titles, labels = ["resultant force of each support"], ["|F| (kN)"]
    if bolts:
        titles.append("anchor bolts: tension (solid) and clamp force (dotted)")
        labels.append("force (kN)")
    f = Figure(titles, labels, xlabel, title=title)
    for n in loads.names:
        f.line(0, x, np.hypot(loads.fx[n], loads.fy[n]) / 1e3, n, "kN", group=n)
    for n in bolts:
        f.line(1, x, np.asarray(loads.tension[n]) / 1e3, f"tension {n}", "kN", group=n)
        f.line(1, x, np.asarray(loads.clamp[n]) / 1e3, f"clamp {n}", "kN", group=n,
               dash="dot")
    f.events([e.t for e in transitions], [e.label for e in transitions])
    x = np.asarray(x, float)
    return f.done(x_range=(x[0], x[-1]) if x.size > 1 and x[-1] != x[0] else None)


def frame_floor_figure(t, rigid, t_mounted, mounted, *, transitions=(), title: str = ""):
    """The force passed to the floor (kN) by a rigid base (the frame load) and by the base on
    its elastic mounts, against time."""
    f = Figure(["force passed to the floor |F|"], ["|F| (kN)"], "t (s)",
               title=title or "Force to the floor: rigid base and on the mounts")
    f.line(0, t, np.asarray(rigid, float) / 1e3, "rigid base", "kN")
    f.line(0, t_mounted, np.asarray(mounted, float) / 1e3, "on the mounts", "kN")
    f.events([e.t for e in transitions], [e.label for e in transitions])
    t = np.asarray(t, float)
    return f.done(x_range=(t[0], t[-1]) if t.size > 1 and t[-1] > t[0] else None)
