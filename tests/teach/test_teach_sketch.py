"""The kinematic sketch of ``eomgen teach`` (eomgen.teach.sketch).

Geometry against closed forms (planar two-link arm) and against Pinocchio's frame placements
(UR5 from example-robot-data); drawings: deterministic bytes in every format, in this process
and in fresh interpreters with other hash seeds, a PNG that is not blank, hostile names.
"""

from __future__ import annotations

import hashlib
import io
import math
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import eomgen
from eomgen.teach.sketch import (
    SketchGeometry, render_sketch, sketch_figure, sketch_geometry, sketch_pose,
)
from support.extras import need

need("matplotlib")

FORMATS = ("svg", "png", "pdf")
TOL = 1e-12
#: Against Pinocchio: the UR5 file's angles are 1.57079632679 (π/2 to 11 digits) and eomgen snaps
#: sines and cosines within 1e-11 of 0 and ±1 to exact values, as tests/test_parsers_urdf.py.
PIN_TOL = 1e-10


def load_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # PUMA 560's published inertias warn by design
        return eomgen.load(path)


@pytest.fixture(scope="module")
def planar():
    return load_quietly(eomgen.example_path("planar_2link"))


@pytest.fixture(scope="module")
def puma():
    return load_quietly(eomgen.example_path("puma560_dh"))


# ----------------------------------------------------------------------------------------------
# Geometry
# ----------------------------------------------------------------------------------------------

def test_sketch_pose_is_30_degrees_for_revolute_and_0_for_prismatic(planar, tmp_path):
    assert sketch_pose(planar) == (math.pi / 6, math.pi / 6)
    cart = eomgen.load(write(tmp_path, CART_POLE))
    assert sketch_pose(cart) == (0.0, math.pi / 6)


def test_planar_2link_matches_the_closed_form(planar):
    values = {p.name: p.value for p in planar.parameters}
    l1, l2, lc1, lc2 = (values[k] for k in ("l1", "l2", "lc1", "lc2"))
    geo = sketch_geometry(planar)
    q1, q2 = geo.q
    assert (q1, q2) == sketch_pose(planar)
    c1, s1 = math.cos(q1), math.sin(q1)
    c12, s12 = math.cos(q1 + q2), math.sin(q1 + q2)
    elbow = np.array([l1 * c1, l1 * s1, 0.0])
    tip = elbow + l2 * np.array([c12, s12, 0.0])
    expected_joints = {"joint1": np.zeros(3), "joint2": elbow, "tip_fixed": tip}
    assert [name for name, _ in geo.joints] == ["joint1", "joint2", "tip_fixed"]
    for name, p in geo.joints:
        np.testing.assert_allclose(p, expected_joints[name], rtol=0, atol=TOL, err_msg=name)
    assert [name for name, _ in geo.coms] == ["link1", "link2"]
    np.testing.assert_allclose(geo.coms[0][1], [lc1 * c1, lc1 * s1, 0], rtol=0, atol=TOL)
    np.testing.assert_allclose(geo.coms[1][1], elbow + lc2 * np.array([c12, s12, 0]),
                               rtol=0, atol=TOL)
    # root -> joint1 has zero length and is left out: the two links remain
    assert len(geo.segments) == 2
    np.testing.assert_allclose(geo.segments[0], [np.zeros(3), elbow], rtol=0, atol=TOL)
    np.testing.assert_allclose(geo.segments[1], [elbow, tip], rtol=0, atol=TOL)
    assert geo.plane == (0, 1)
    assert geo.placeholder_parameters == ()


def test_planar_2link_at_a_given_pose(planar):
    geo = sketch_geometry(planar, q=np.array([0.3, -1.1]))
    assert geo.q == (0.3, -1.1) and all(type(x) is float for x in geo.q)
    np.testing.assert_allclose(dict(geo.joints)["tip_fixed"],
                               [math.cos(0.3) + math.cos(-0.8), math.sin(0.3) + math.sin(-0.8), 0],
                               rtol=0, atol=TOL)
    with pytest.raises(ValueError, match="shape"):
        sketch_geometry(planar, q=[0.1, 0.2, 0.3])


def test_geometry_is_plain_frozen_data(planar):
    geo = sketch_geometry(planar)
    assert isinstance(geo, SketchGeometry)
    with pytest.raises(AttributeError):
        geo.plane = None
    for _, p in geo.joints + geo.coms:
        assert len(p) == 3 and all(type(x) is float for x in p)
    assert geo == sketch_geometry(planar)


def test_puma_is_not_planar(puma):
    geo = sketch_geometry(puma)
    assert geo.plane is None
    assert len(geo.q) == 6
    # the wrist joints 4, 5 and 6 meet at the wrist centre
    at = dict(geo.joints)
    np.testing.assert_allclose(at["joint4"], at["joint6"], rtol=0, atol=TOL)


def test_ur5_matches_pinocchio_frame_placements(erd_robots_dir):
    pin = need("pinocchio")
    path = erd_robots_dir / "ur_description" / "urdf" / "ur5_robot.urdf"
    model = load_quietly(path)
    pmodel = pin.buildModelFromUrdf(str(path))
    pdata = pmodel.createData()
    rng = np.random.default_rng(5)
    for q in (None, rng.uniform(-np.pi, np.pi, model.dof)):
        geo = sketch_geometry(model, q)
        qp = np.zeros(pmodel.nq)
        for name, x in zip(model.joint_names, geo.q):
            qp[pmodel.joints[pmodel.getJointId(name)].idx_q] = x
        pin.forwardKinematics(pmodel, pdata, qp)
        pin.updateFramePlacements(pmodel, pdata)
        assert [name for name, _ in geo.joints] == [j.name for j in model.joints]
        for joint, (name, p) in zip(model.joints, geo.joints):
            if joint.type.is_movable:
                expected = pdata.oMi[pmodel.getJointId(name)].translation
            else:
                expected = pdata.oMf[pmodel.getFrameId(name)].translation
            np.testing.assert_allclose(p, expected, rtol=0, atol=PIN_TOL, err_msg=name)
        # each link's centre of mass, and their mass-weighted mean against Pinocchio's
        masses = {link.name: float(link.inertial.mass) for link in model.links
                  if link.inertial is not None}
        for name, c in geo.coms:
            frame = pdata.oMf[pmodel.getFrameId(name, pin.BODY)]
            local = [float(x) for x in model.link_by_name[name].inertial.com]
            np.testing.assert_allclose(c, frame.act(np.array(local)), rtol=0, atol=PIN_TOL)
        # Pinocchio's centre of mass leaves out the bodies fixed to the universe (base_link)
        moving = [(name, c) for name, c in geo.coms if moves(model, name)]
        assert len(moving) == len(geo.coms) - 1
        total = sum(masses[name] * np.array(c) for name, c in moving)
        mean = total / sum(masses[name] for name, _ in moving)
        np.testing.assert_allclose(mean, pin.centerOfMass(pmodel, pdata, qp), rtol=0, atol=PIN_TOL)
    assert geo.plane is None


def moves(model, link: str) -> bool:
    """Whether a movable joint lies between ``link`` and the root."""
    while link in model.parent_joint:
        joint = model.parent_joint[link]
        if joint.type.is_movable:
            return True
        link = joint.parent
    return False


CART_POLE = """
name: cart_pole
gravity: [0, -9.81, 0]
parameters:
  m: {value: 1.0, description: "pole mass [kg]"}
  l: {description: "pole length [m], no value"}
links:
  - name: rail
  - name: cart
    mass: 2.0
  - name: pole
    mass: m
    com: [0, l, 0]
joints:
  - name: slide
    type: prismatic
    parent: rail
    child: cart
    axis: [1, 0, 0]
  - name: swing
    type: revolute
    parent: cart
    child: pole
    axis: [0, 0, 1]
"""


def write(tmp_path, text: str, name: str = "robot.yaml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_parameter_without_value_is_a_placeholder_of_1(tmp_path):
    model = eomgen.load(write(tmp_path, CART_POLE))
    geo = sketch_geometry(model, q=[0.25, 0.0])
    assert geo.placeholder_parameters == ("l",)
    at = dict(geo.coms)
    np.testing.assert_allclose(at["pole"], [0.25, 1.0, 0.0], rtol=0, atol=TOL)  # l drawn as 1
    np.testing.assert_allclose(dict(geo.joints)["slide"], [0.25, 0, 0], rtol=0, atol=TOL)
    # a prismatic joint in the plane, a revolute joint across it: still planar, in x-y
    assert geo.plane == (0, 1)
    # the pole ends the chain: drawn from its origin to its centre of mass
    np.testing.assert_allclose(geo.segments[-1], [[0.25, 0, 0], [0.25, 1, 0]], rtol=0, atol=TOL)
    assert render_sketch(model, "png").startswith(b"\x89PNG")


# ----------------------------------------------------------------------------------------------
# Drawing
# ----------------------------------------------------------------------------------------------

def digests(models) -> list[str]:
    return [hashlib.sha256(render_sketch(m, fmt)).hexdigest() for m in models for fmt in FORMATS]


SUBPROCESS = """
import hashlib, warnings
warnings.simplefilter("ignore")
import eomgen
from eomgen.teach.sketch import render_sketch
for name in ("planar_2link", "puma560_dh"):
    m = eomgen.load(eomgen.example_path(name))
    for fmt in ("svg", "png", "pdf"):
        print(hashlib.sha256(render_sketch(m, fmt)).hexdigest())
"""


@pytest.mark.slow
def test_render_is_deterministic_in_process_and_across_interpreters(planar, puma):
    first = digests([planar, puma])
    assert digests([planar, puma]) == first
    # One other interpreter, its hash seed other than this one's (which is random unless the
    # caller fixed it): the same bytes (a second interpreter tested no more than the first).
    seed = "12345" if os.environ.get("PYTHONHASHSEED") != "12345" else "0"
    env = dict(os.environ, PYTHONHASHSEED=seed)
    out = subprocess.run([sys.executable, "-c", SUBPROCESS], env=env, check=True,
                         capture_output=True, text=True).stdout.split()
    assert out == first


def test_render_formats_have_their_signatures(planar):
    assert render_sketch(planar, "pdf").startswith(b"%PDF")
    svg = render_sketch(planar, "svg")
    assert b"<svg" in svg and b"<dc:date>" not in svg
    with pytest.raises(ValueError, match="unknown sketch format"):
        render_sketch(planar, "jpeg")


@pytest.mark.parametrize("which", ["planar", "puma"])
def test_png_decodes_and_is_not_blank(which, request):
    PIL = need("PIL.Image")
    model = request.getfixturevalue(which)
    image = PIL.open(io.BytesIO(render_sketch(model, "png")))
    width, height = image.size
    assert 500 <= width <= 1200 and 400 <= height <= 1000 and width > height
    grey = np.asarray(image.convert("L"))
    assert (grey < 80).sum() > 2000  # lines, markers, labels
    assert (grey > 240).mean() > 0.5  # on a white page


def test_figure_is_small_and_titled_without_pyplot(planar, puma):
    from matplotlib.figure import Figure

    for model, dims in ((planar, "rectilinear"), (puma, "3d")):
        fig = sketch_figure(model)
        assert isinstance(fig, Figure)
        assert tuple(fig.get_size_inches()) == (5.0, 4.0)
        assert fig.axes[0].name == dims
        pose = ", ".join(["30°"] * model.dof)
        assert fig.get_suptitle() == f"{model.name}\n(pose drawn: q = ({pose}))"
    source = open(sys.modules["eomgen.teach.sketch"].__file__, encoding="utf-8").read()
    assert "matplotlib.pyplot" not in source and "import pyplot" not in source


def test_hostile_robot_name_is_drawn_literally(tmp_path):
    hostile = r"evil $\nope{x$ robot \ $$ 100% \$"
    text = CART_POLE.replace("name: cart_pole", "name: '" + hostile + "'")
    model = eomgen.load(write(tmp_path, text))
    assert model.name == hostile
    for fmt in FORMATS:  # mathtext would raise on "\nope{x"
        assert render_sketch(model, fmt)
    fig = sketch_figure(model)
    assert fig.get_suptitle().splitlines()[0] == hostile


@pytest.mark.parametrize("gravity", ["[0, -g, 0]", "[0, g, 0]", "[g, 0, 0]"])
def test_planar_view_turns_gravity_down_the_page(tmp_path, gravity):
    """Whatever the root frame, the planar view has gravity pointing down the page: the
    hatched ground sits below the root joint, and the robot's vertical extent is unchanged."""
    from matplotlib.patches import Polygon

    text = eomgen.example_path("planar_2link").read_text().replace(
        "gravity: [0, -g, 0]", f"gravity: {gravity}")
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    fig = sketch_figure(eomgen.load(path))
    ax = fig.axes[0]
    ground = next(p for p in ax.patches if isinstance(p, Polygon))
    xy = ground.get_xy()[:4]  # the closed polygon repeats its first corner
    assert xy[:, 1].max() < 0 and abs(xy[:, 0].mean()) < 1e-9  # straight below the root
