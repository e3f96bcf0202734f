"""The kinematic sketch of a robot for a student handout (``eomgen teach``).

Two stages, plain data between them:

* :func:`~eomgen.teach.sketch_geometry.sketch_geometry` runs the numeric forward kinematics
  (:func:`eomgen.numeric.link_poses`) at one pose and returns a
  :class:`~eomgen.teach.sketch_geometry.SketchGeometry`: joint origins, centres of mass, the
  link segments and, when the robot moves in a plane, which plane (:mod:`eomgen.teach.
  sketch_geometry`).
* :func:`sketch_figure` draws that geometry as a textbook figure with matplotlib (links as
  thick grey lines, revolute joints as circles, prismatic joints as squares, a hatched base,
  centres of mass as ⊕ markers labelled c₁, c₂…, joint labels q₁, q₂…, the gravity arrow g and
  the base frame axes). Planar robots get a 2-D view of their motion plane with the joint
  angle arcs; others a 3-D view. :func:`render_sketch` turns it into SVG, PNG or PDF bytes,
  identical for identical input.

Frames and units
----------------
Every point is in the *world* frame, which is the root link frame (as in :mod:`eomgen.numeric`),
in metres. Joint angles are in radians (degrees in the figure title), prismatic joint positions
in metres. ``q[k]`` belongs to ``model.movable_joints[k]`` (description order).

No pyplot: figures are :class:`matplotlib.figure.Figure` objects with their own Agg canvas, so
nothing is registered globally and the module is safe to use from a server or a test. matplotlib
is imported only by the drawing functions; :func:`sketch_geometry` needs NumPy alone.

Examples
--------
>>> import eomgen
>>> from eomgen.teach.sketch import sketch_geometry
>>> geo = sketch_geometry(eomgen.load(eomgen.example_path("planar_2link")))
>>> geo.plane                       # the x-y plane of the root frame
(0, 1)
>>> [round(x, 4) for x in dict(geo.joints)["joint2"]]   # (l1 cos q1, l1 sin q1, 0), q1 = 30°
[0.866, 0.5, 0.0]
"""

from __future__ import annotations

import io
import math
import textwrap
import warnings

import numpy as np

from ..model import RobotModel
from ..numeric import link_poses, numeric_model
# What is drawn (plain data, NumPy alone); its names are also imported from here.
from .sketch_geometry import (PLACEHOLDER_VALUE, SKETCH_ANGLE, TOL, SketchGeometry,
                              sketch_geometry, sketch_pose)

#: Figure size [in] and the fixed 3-D view (elevation, azimuth) [deg].
FIGSIZE = (5.0, 4.0)
VIEW_3D = (22.0, -58.0)

#: rcParams applied on top of matplotlib's defaults while drawing and saving, for a small,
#: readable and byte-for-byte reproducible figure.
RC = {
    "font.size": 9.0,
    "font.family": "DejaVu Sans",
    "mathtext.fontset": "dejavusans",
    "svg.hashsalt": "eomgen-sketch",
    "svg.fonttype": "path",
    "pdf.fonttype": 42,
    "savefig.dpi": 150,
    "savefig.bbox": None,
    "path.simplify": False,
    "axes.unicode_minus": True,
}

#: Metadata for ``Figure.savefig`` per format: no dates, so the bytes do not depend on the time.
_METADATA = {
    "svg": {"Date": None},
    "pdf": {"CreationDate": None, "ModDate": None},
    "png": {},
}

_AXIS_NAMES = "xyz"


# ----------------------------------------------------------------------------------------------
# Drawing
# ----------------------------------------------------------------------------------------------

class _Style:
    """Sizes [points] and colours of the drawing elements."""

    link_grey = "0.55"
    link_width = 5.0
    joint_size = 11.0
    com_size = 9.0
    thin = 0.9
    label_gap = 8.0  # offset of a label from its point [points]


def sketch_figure(model: RobotModel, q=None):
    """The kinematic sketch of ``model`` at ``q`` as a matplotlib figure.

    A planar robot (``SketchGeometry.plane`` not None) is drawn in its motion plane with equal
    scales and, for each revolute joint, its angle arc: from the dashed direction the child
    link has at ``q = 0`` to its direction in the pose drawn. Any other robot is drawn in an
    orthographic 3-D view (fixed elevation and azimuth :data:`VIEW_3D`, equal scales). Labels:
    ``q_k`` at the joint of ``q[k-1]``; ``c_k`` at the centre of mass of the link moved by
    ``q_k`` (``c_0`` for links fixed to the root, primes when several links move with the same
    joint); ``x_0, y_0, z_0`` the root frame axes; ``g`` the direction of gravity (left out
    when gravity is zero or not a number). The title names the robot and the pose drawn.

    Parameters
    ----------
    model : RobotModel
    q : (n,) array_like, optional
        Joint positions in ``model.movable_joints`` order [rad or m]; :func:`sketch_pose` when
        omitted.

    Returns
    -------
    matplotlib.figure.Figure
        About 5 × 4 in, with its own Agg canvas (no pyplot, nothing global). Saving it
        yourself uses your rcParams at save time; :func:`render_sketch` gives reproducible
        bytes.
    """
    import matplotlib  # start-up time: only drawing needs matplotlib

    with matplotlib.rc_context():
        matplotlib.rcdefaults()  # independent of the user's matplotlibrc and style
        matplotlib.rcParams.update(RC)
        return _figure(model, sketch_geometry(model, q))


def render_sketch(model: RobotModel, fmt: str, q=None) -> bytes:
    """The sketch of ``model`` (see :func:`sketch_figure`) as file bytes.

    Parameters
    ----------
    model : RobotModel
    fmt : {"svg", "png", "pdf"}
    q : (n,) array_like, optional
        Joint positions [rad or m]; :func:`sketch_pose` when omitted.

    Returns
    -------
    bytes
        The file, identical for identical input: fixed SVG hash salt, no dates in the metadata,
        matplotlib's default rcParams plus :data:`RC` whatever the user's configuration.
    """
    if fmt not in _METADATA:
        raise ValueError(f"unknown sketch format {fmt!r}; expected one of svg, png, pdf")
    import matplotlib  # start-up time: only drawing needs matplotlib

    with matplotlib.rc_context():
        matplotlib.rcdefaults()
        matplotlib.rcParams.update(RC)
        fig = _figure(model, sketch_geometry(model, q))
        out = io.BytesIO()
        with warnings.catch_warnings():  # a name in a script DejaVu lacks draws as boxes
            warnings.filterwarnings("ignore", message=r"Glyph \d+ .* missing from font")
            fig.savefig(out, format=fmt, metadata=_METADATA[fmt])
    return out.getvalue()


def _numeric_gravity(model: RobotModel) -> np.ndarray | None:
    """``model.gravity`` [m/s²] with the parameters' own values; None when not a number."""
    values = model.parameter_values
    try:
        g = np.array([float(x.subs(values)) for x in model.gravity])
    except TypeError:  # a parameter without a value: the direction is unknown
        return None
    return g if np.all(np.isfinite(g)) and np.linalg.norm(g) > TOL else None


def _format_pose(model: RobotModel, q) -> str:
    parts = [f"{math.degrees(x):.4g}°" if j.rotates else f"{x:.4g} m"
             for j, x in zip(model.movable_joints, q)]
    return textwrap.fill("(" + ", ".join(parts) + ")", width=60, break_long_words=False)


def _com_names(model: RobotModel, geo: SketchGeometry) -> list[str]:
    """Mathtext label bodies of ``geo.coms``: ``c_{k}`` for the link moved by ``q_k``."""
    index = {j.name: k + 1 for k, j in enumerate(model.movable_joints)}
    seen: dict[int, int] = {}
    names = []
    for link, _ in geo.coms:
        k = 0
        while link in model.parent_joint:
            joint = model.parent_joint[link]
            if joint.name in index:
                k = index[joint.name]
                break
            link = joint.parent
        primes = seen.get(k, 0)
        seen[k] = primes + 1
        names.append(f"c_{{{k}}}" + "'" * primes)
    return names


def _merged(items, tol: float):
    """``[(point, mathtext body)]`` with labels of points closer than ``tol`` joined."""
    groups: list[tuple[np.ndarray, list[str]]] = []
    for p, body in items:
        for q, bodies in groups:
            if np.linalg.norm(p - q) < tol:
                bodies.append(body)
                break
        else:
            groups.append((np.asarray(p, float), [body]))
    return [(p, "$" + ", ".join(bodies) + "$") for p, bodies in groups]


def _com_marker():
    """The textbook centre-of-mass symbol's black part: two opposite quadrants of a circle."""
    from matplotlib.path import Path  # start-up time: only drawing needs matplotlib

    return Path.make_compound_path(Path.wedge(0, 90), Path.wedge(180, 270))


def _draw_com(ax, xy, size: float, zorder: float) -> None:
    ax.plot(*xy, marker="o", ms=size, mfc="white", mec="black", mew=1.0, ls="", zorder=zorder)
    ax.plot(*xy, marker=_com_marker(), ms=size, mfc="black", mew=0.0, ls="", zorder=zorder)


def _arrow(ax, tail, head, lw: float, size: float, **kw) -> None:
    ax.annotate("", xy=head, xytext=tail, arrowprops=dict(
        arrowstyle="-|>", color="black", lw=lw, shrinkA=0, shrinkB=0, mutation_scale=size), **kw)


def _label(ax, xy, text: str, direction, zorder: float = 9) -> None:
    """``text`` at ``_Style.label_gap`` points from ``xy`` along the 2-D ``direction``,
    aligned so that it extends away from the point."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d) if np.linalg.norm(d) > 0 else np.array([1.0, 0.0])
    ha = "left" if d[0] > 0.35 else "right" if d[0] < -0.35 else "center"
    va = "bottom" if d[1] > 0.35 else "top" if d[1] < -0.35 else "center"
    ax.annotate(text, xy=xy, xytext=_Style.label_gap * d, textcoords="offset points",
                ha=ha, va=va, zorder=zorder)


def _gravity_arrow(ax, down2d: np.ndarray) -> None:
    """An arrow along the projected gravity in the top right corner, labelled g."""
    if np.linalg.norm(down2d) < 1e-6:  # gravity along the line of sight
        return
    down2d = down2d / np.linalg.norm(down2d)
    centre = np.array([0.9, 0.78])
    _arrow(ax, centre - 0.08 * down2d, centre + 0.08 * down2d, 1.3, 12,
           xycoords="axes fraction", textcoords="axes fraction")
    side = np.array([-down2d[1], down2d[0]])
    ax.annotate("$g$", xy=centre + 0.05 * side, xycoords="axes fraction", ha="center",
                va="center", fontsize=10)


def _figure(model: RobotModel, geo: SketchGeometry):
    # start-up time: only drawing needs matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=FIGSIZE)
    FigureCanvasAgg(fig)
    points = np.array([p for _, p in geo.joints] + [p for _, p in geo.coms] + [(0.0, 0.0, 0.0)])
    scale = float(np.max(np.linalg.norm(points, axis=1)))
    scale = scale if scale > TOL else 1.0
    if geo.plane is not None:
        _draw_planar(fig, model, geo, scale, _numeric_gravity(model))
    else:
        _draw_3d(fig, model, geo, scale, _numeric_gravity(model))
    # The robot's name is never parsed as mathtext (parse_math=False): exact for any name,
    # '$' and '\' included, where escaping would still leave corner cases.
    title = f"{model.name}\n(pose drawn: q = {_format_pose(model, geo.q)})"
    fig.suptitle(title, fontsize=9.5, parse_math=False, y=0.97)
    if geo.placeholder_parameters:
        note = "drawn with value 1: " + ", ".join(geo.placeholder_parameters)
        fig.text(0.02, 0.02, note, fontsize=8, color="0.3", parse_math=False)
    return fig


def _world_axes(model: RobotModel, geo: SketchGeometry) -> dict[str, np.ndarray]:
    """Joint name -> world direction of the movable joint's axis at the pose drawn."""
    nm = numeric_model(model, values=dict.fromkeys(geo.placeholder_parameters,
                                                   PLACEHOLDER_VALUE))
    poses = link_poses(nm, geo.q)
    return {j.name: poses[j.child][0] @ nm.axis[nm.body_names.index(j.child)]
            for j in model.movable_joints}


def _fit_limits(ax, pts: np.ndarray, pad: float, box: tuple[float, float]) -> None:
    """Limits around ``pts`` with equal scales on both axes for an axes of ``box`` inches."""
    lo, hi = pts.min(axis=0) - pad, pts.max(axis=0) + pad
    centre, span = 0.5 * (lo + hi), hi - lo
    per_inch = max(span[0] / box[0], span[1] / box[1])
    half = 0.5 * per_inch * np.array(box)
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
    ax.set_aspect("equal", adjustable="box")


def _draw_planar(fig, model: RobotModel, geo: SketchGeometry, scale: float, gravity) -> None:
    from matplotlib.patches import Polygon  # start-up time: only drawing needs matplotlib

    i, j = geo.plane
    rect = (0.03, 0.03, 0.94, 0.8)
    ax = fig.add_axes(rect)
    ax.set_axis_off()

    # The view is turned in its plane so that gravity points down the page, as a student would
    # draw it (a turn keeps the handedness, so the angle arcs keep their sense).
    turn_view = np.eye(2)
    if gravity is not None and math.hypot(gravity[i], gravity[j]) > TOL:
        phi = -math.pi / 2 - math.atan2(gravity[j], gravity[i])
        if abs(phi) > 1e-12:
            turn_view = np.array([[math.cos(phi), -math.sin(phi)],
                                  [math.sin(phi), math.cos(phi)]])

    def v(p):
        return turn_view @ np.array([p[i], p[j]], dtype=float)

    joint_at = {name: v(p) for name, p in geo.joints}
    com_at = {name: v(p) for name, p in geo.coms}
    pts = [np.zeros(2), *joint_at.values(), *com_at.values()]

    # Base: a ground line under the root origin, hatched on the far side.
    down = np.array([0.0, -1.0]) if gravity is None else v(gravity)
    down = down / np.linalg.norm(down) if np.linalg.norm(down) > TOL else np.array([0.0, -1.0])
    side = np.array([-down[1], down[0]])
    w, h, top = 0.16 * scale, 0.06 * scale, down * 0.08 * scale
    ground = [top - side * w, top + side * w, top + side * w + down * h, top - side * w + down * h]
    ax.add_patch(Polygon(ground, closed=True, facecolor="white", edgecolor="black",
                         hatch="////", linewidth=0.0, zorder=1))
    ax.plot(*np.array(ground[:2]).T, color="black", lw=1.6, zorder=2)
    ax.plot(*np.array([np.zeros(2), top]).T, color=_Style.link_grey, lw=_Style.link_width,
            solid_capstyle="butt", zorder=2)
    pts += ground

    for a, b in geo.segments:
        ax.plot(*np.array([v(a), v(b)]).T, color=_Style.link_grey, lw=_Style.link_width,
                solid_capstyle="round", zorder=3)

    # Root frame axes, along the view's axes.
    for e, name in ((turn_view[:, 0], _AXIS_NAMES[i]), (turn_view[:, 1], _AXIS_NAMES[j])):
        end = 0.2 * scale * e
        _arrow(ax, (0.0, 0.0), end, _Style.thin, 8, zorder=6)
        _label(ax, end, f"${name}_0$", e, zorder=6)
        pts.append(end)

    # Joints, their angle arcs and labels.
    children: dict[str, list[str]] = {}
    for jt in model.joints:
        children.setdefault(jt.parent, []).append(jt.name)
    world_axis = _world_axes(model, geo)
    view_normal = np.cross(np.eye(3)[i], np.eye(3)[j])
    turn = {}  # link -> sign of its joint's arc, for the side of its c label
    for k, jt in enumerate(model.movable_joints):
        p = joint_at[jt.name]
        ax.plot(*p, marker="o" if jt.rotates else "s", ms=_Style.joint_size,
                mfc="white", mec="black", mew=1.4, zorder=5)
        label = f"$q_{{{k + 1}}}$"
        ahead = [joint_at[c] for c in children.get(jt.child, ())]
        ahead += [com_at[jt.child]] if jt.child in com_at else []
        ahead = [t - p for t in ahead if np.linalg.norm(t - p) > 1e-6 * scale]
        if jt.rotates and ahead:
            sign = math.copysign(1.0, float(view_normal @ world_axis[jt.name]))
            turn[jt.child] = math.copysign(1.0, sign * geo.q[k])
            pts += _angle_arc(ax, p, ahead[0], sign * geo.q[k], 0.3 * scale, label)
        else:
            _label(ax, p, label, (-1.0, 1.2))

    # Centres of mass, labelled on the side of the link away from its angle arc.
    for (link, _), name in zip(geo.coms, _com_names(model, geo)):
        xy = com_at[link]
        _draw_com(ax, xy, _Style.com_size, 8)
        d = xy - (joint_at[model.parent_joint[link].name] if link in model.parent_joint
                  else np.zeros(2))
        normal = np.array([-d[1], d[0]]) * turn.get(link, 1.0)
        _label(ax, xy, f"${name}$", normal if np.linalg.norm(d) > TOL else (1.0, -1.0))

    box = (FIGSIZE[0] * rect[2], FIGSIZE[1] * rect[3])
    _fit_limits(ax, np.array(pts), 0.12 * scale, box)
    if gravity is not None:
        _gravity_arrow(ax, v(gravity))


def _angle_arc(ax, p, direction, angle: float, radius: float, label: str) -> list:
    """A dashed zero line, an arc from it to ``direction`` sweeping ``angle`` [rad] and the
    label at the arc's middle. Returns the points used, for the limits."""
    theta = math.atan2(direction[1], direction[0])
    theta0 = theta - angle
    ref_end = p + np.array([math.cos(theta0), math.sin(theta0)]) * radius * 1.6
    ax.plot(*np.array([p, ref_end]).T, color="0.35", lw=0.8, ls=(0, (3, 2)), zorder=4)
    t = np.linspace(theta0, theta, 40)
    arc = p + radius * np.column_stack([np.cos(t), np.sin(t)])
    ax.plot(*arc[:-1].T, color="black", lw=_Style.thin, zorder=4)
    if abs(angle) > 0.05:
        _arrow(ax, arc[-4], arc[-1], _Style.thin, 7, zorder=4)
    mid = 0.5 * (theta0 + theta)
    at = p + 1.3 * radius * np.array([math.cos(mid), math.sin(mid)])
    ax.text(*at, label, ha="center", va="center", zorder=7)
    return [ref_end, at]


def _draw_3d(fig, model: RobotModel, geo: SketchGeometry, scale: float, gravity) -> None:
    from mpl_toolkits.mplot3d import proj3d  # start-up time: only drawing needs matplotlib
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax = fig.add_axes((0.0, 0.0, 1.0, 0.86), projection="3d")
    ax.view_init(elev=VIEW_3D[0], azim=VIEW_3D[1])
    ax.set_proj_type("ortho")
    ax.set_axis_off()
    ax.computed_zorder = False  # draw in the order given: base, links, markers, labels

    joint_at = {name: np.array(p) for name, p in geo.joints}
    com_at = {name: np.array(p) for name, p in geo.coms}
    pts = [np.zeros(3), *joint_at.values(), *com_at.values()]

    # Base: a hatched plate just below the root origin, across gravity (z up by default).
    up = np.array([0.0, 0.0, 1.0]) if gravity is None else -gravity / np.linalg.norm(gravity)
    e1 = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    centre = -0.06 * scale * up
    w = 0.16 * scale
    plate = [centre + w * (a * e1 + b * e2) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    ax.add_collection3d(Poly3DCollection([plate], facecolor="0.93", edgecolor="black",
                                         linewidths=0.8, hatch="////", zorder=1))
    ax.plot(*np.array([np.zeros(3), centre]).T, color=_Style.link_grey, lw=_Style.link_width,
            zorder=2)
    pts += plate

    for a, b in geo.segments:
        ax.plot(*np.array([a, b]).T, color=_Style.link_grey, lw=_Style.link_width,
                solid_capstyle="round", zorder=3)
    for n in range(3):
        e = 0.3 * scale * np.eye(3)[n]
        ax.quiver(0, 0, 0, *e, color="black", lw=_Style.thin, arrow_length_ratio=0.2, zorder=4)
        pts.append(e)
    for jt in model.movable_joints:
        ax.plot(*joint_at[jt.name], marker="o" if jt.rotates else "s",
                ms=_Style.joint_size, mfc="white", mec="black", mew=1.3, ls="", zorder=5)
    for link in com_at:
        _draw_com(ax, com_at[link], _Style.com_size - 3, 6)

    # Equal scales: a cube around everything drawn.
    pts = np.array(pts)
    mid = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    half = 0.5 * float(np.max(pts.max(axis=0) - pts.min(axis=0))) + 0.05 * scale
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_box_aspect((1, 1, 1), zoom=1.3)

    # Labels in screen space: project to the axes' 2-D data coordinates, offset in points.
    M = ax.get_proj()

    def flat(p):
        x, y, _ = proj3d.proj_transform(p[0], p[1], p[2], M)
        return np.array([float(x), float(y)])

    origin = flat(np.zeros(3))
    for n in range(3):
        end = flat(0.3 * scale * np.eye(3)[n])
        _label(ax, end, f"${_AXIS_NAMES[n]}_0$", end - origin)
    joints = [(flat(joint_at[jt.name]), f"q_{{{k + 1}}}")
              for k, jt in enumerate(model.movable_joints)]
    coms = [(flat(com_at[link]), name)
            for (link, _), name in zip(geo.coms, _com_names(model, geo))]
    # Labels of points closer than 4 % of the drawing on screen are joined ("q_4, q_5, q_6").
    flat_pts = np.array([flat(p) for p in pts])
    tol = 0.04 * float(np.max(flat_pts.max(axis=0) - flat_pts.min(axis=0)))
    for xy, text in _merged(joints, tol):
        _label(ax, xy, text, (-1.0, 0.8))
    for xy, text in _merged(coms, tol):
        _label(ax, xy, text, (1.0, -0.8))
    if gravity is not None:
        _gravity_arrow(ax, flat(gravity / np.linalg.norm(gravity)) - flat(np.zeros(3)))


__all__ = [
    "SketchGeometry",
    "sketch_pose",
    "sketch_geometry",
    "sketch_figure",
    "render_sketch",
    "SKETCH_ANGLE",
    "PLACEHOLDER_VALUE",
]
