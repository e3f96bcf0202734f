"""Floating bases (eomgen.model.floating; the maps: eomgen.numeric.floating_base): six virtual
joints against Pinocchio's free flyer.

Reference: Pinocchio's own URDF reader with ``JointModelFreeFlyer`` (independent of eomgen's
parser and of its numeric Newton–Euler), its dynamics mapped to Euler coordinates through
``v = T q̇`` (M = Tᵀ M_pin T, C q̇ = Tᵀ(h_pin + M_pin Ṫ q̇), g = Tᵀ g_pin).
"""

from __future__ import annotations


import numpy as np
import pytest

import eomgen
from support import erd_robots_dir, floating_states, load_quietly, relative
from eomgen import numeric
from eomgen.model import floating
from eomgen.numeric import floating_base
from eomgen.errors import InvalidInertiaError, KinematicTreeError, SceneError
from eomgen.model import Inertial, Joint, JointType, Link, build_model, vec3
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support.robots import SOLO, FreeFlyerReference
from support.extras import need

TALOS = "talos_data/robots/talos_reduced.urdf"
LEGS = ("leg_left_6_link", "leg_right_6_link")


@pytest.fixture(scope="module")
def solo():
    need("pinocchio", reason="Pinocchio is the reference")
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    path = robots / SOLO
    model = floating.add_floating_base(load_quietly(path))
    return model, FreeFlyerReference(path, model.joint_names)


def test_floating_model_layout(solo):
    model, _ = solo
    assert model.joint_names[:6] == floating.EULER_JOINTS
    assert model.root == floating.WORLD and model.dof == 18
    assert not [n for n in model.notices if n.kind.name == "FLOATING_BASE"]


def test_solo12_matches_pinocchio_free_flyer(solo):
    model, ref = solo
    nm = numeric.numeric_model(model)
    for q, qd in floating_states(18, 4):
        M, Cqd, g = ref.dynamics(q, qd)
        assert relative(numeric.M_rnea(nm, q), M) <= 1e-10
        assert relative(numeric.coriolis_times_qd(nm, q, qd), Cqd) <= 1e-10
        assert relative(numeric.gravity_torques(nm, q), g) <= 1e-10


@pytest.mark.slow
def test_solo12_symbolic_derivation_matches_pinocchio(solo):
    from eomgen.symbolic.evaluate import compile_program

    model, ref = solo
    dyn = eomgen.derive(model, outputs=("M", "C", "g"))
    report = eomgen.verify(dyn, samples=3)  # SPD, Ṁ − 2C skew, against Newton–Euler
    assert all(check.passed for check in report.checks), report
    f = compile_program(dyn.program, dyn.q + dyn.qd)
    for q, qd in floating_states(18, 3, seed=1):
        out = f(*q, *qd)
        M, Cqd, g = ref.dynamics(q, qd)
        assert relative(out["M"], M) <= 1e-10
        assert relative(out["C"] @ qd, Cqd) <= 1e-10
        assert relative(out["g"].ravel(), g) <= 1e-10


def test_talos_legs_scene_matches_pinocchio():
    need("pinocchio", reason="Pinocchio is the reference")
    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    path = erd_robots_dir() / TALOS
    robot = load_quietly(path)
    scene = load_scene("talos_legs.yaml", text="version: 1\nfloating_base: euler\ntips: ["
                       + ", ".join(LEGS) + "]\n")
    legs, report = apply_scene(robot, scene)
    assert legs.dof == 18 and legs.joint_names[:6] == floating.EULER_JOINTS
    assert any("floats" in note for note in report.notes)
    others = [j.name for j in robot.movable_joints if j.name not in legs.joint_names]
    ref = FreeFlyerReference(path, legs.joint_names, locked=others)
    nm = numeric.numeric_model(legs)
    for q, qd in floating_states(18, 3, seed=2):
        M, Cqd, g = ref.dynamics(q, qd)
        assert relative(numeric.M_rnea(nm, q), M) <= 1e-10
        assert relative(numeric.coriolis_times_qd(nm, q, qd), Cqd) <= 1e-10
        assert relative(numeric.gravity_torques(nm, q), g) <= 1e-10


def test_state_maps_round_trip_and_match_pinocchio_kinematics(solo):
    model, ref = solo
    pin = ref.pin
    for q, qd in floating_states(18, 3, seed=3):
        q_ff, v = floating_base.to_free_flyer(q, qd)
        assert np.isclose(np.linalg.norm(q_ff[3:7]), 1.0)
        q2, qd2 = floating_base.from_free_flyer(q_ff, v)
        assert np.allclose(q2, q, atol=1e-12) and np.allclose(qd2, qd, atol=1e-12)
        # the base pose eomgen's kinematics gives is Pinocchio's free-flyer placement
        q_pin, _ = ref.state(q, qd)
        pin.forwardKinematics(ref.model, ref.data, q_pin)
        placement = ref.data.oMi[1]
        poses = numeric.link_poses(numeric.numeric_model(model), q)
        R, p = poses["base_link"]
        assert np.allclose(placement.rotation, R, atol=1e-14)
        assert np.allclose(placement.translation, p, atol=1e-14)


def test_velocity_map_derivative_is_a_finite_difference():
    rng = np.random.default_rng(4)
    q, qd = rng.uniform(-1, 1, 8), rng.uniform(-1, 1, 8)
    h = 1e-6
    T = floating_base.velocity_map
    fd = (T(q + h * qd) - T(q - h * qd)) @ qd / (2 * h)
    assert np.allclose(floating_base.velocity_map_dot_qd(q, qd), fd, atol=1e-8)


def test_body_angular_velocity_is_that_of_the_rotation():
    """ω_b = E(θ, φ) [ψ̇, θ̇, φ̇] is Rᵀ Ṙ (as a vector), by finite differences."""
    rng = np.random.default_rng(5)
    angles, rates = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
    h = 1e-6
    R = floating_base.base_rotation(*angles)
    Rdot = (floating_base.base_rotation(*(angles + h * rates))
            - floating_base.base_rotation(*(angles - h * rates))) / (2 * h)
    W = R.T @ Rdot
    assert np.allclose([W[2, 1], W[0, 2], W[1, 0]],
                       floating_base.euler_rate_matrix(angles[1], angles[2]) @ rates, atol=1e-8)
    assert np.isclose(np.linalg.det(floating_base.euler_rate_matrix(0.3, 0.7)), -np.cos(0.3))


def test_singularity_is_detected_and_real(solo):
    model, _ = solo
    q = np.zeros(18)
    q[4] = np.pi / 2
    assert floating_base.euler_singularity(q) < 1e-15
    with pytest.raises(floating_base.EulerSingularityError, match="singularity"):
        floating_base.check_euler(q)
    q_ff, v = floating_base.to_free_flyer(q, np.zeros(18))
    with pytest.raises(floating_base.EulerSingularityError):
        floating_base.from_free_flyer(q_ff, v)
    # the mass matrix in Euler coordinates is singular there: yaw and roll move alike
    M = numeric.M_rnea(numeric.numeric_model(model), q)
    assert np.linalg.eigvalsh(M).min() < 1e-12 * np.linalg.eigvalsh(M).max()
    q[4] = 0.5
    floating_base.check_euler(q)


def _point_mass_robot(root_mass):
    """A root link and one pendulum link carrying a point mass."""
    bob = Inertial(1.0, (0, 0, -0.5))
    root = Inertial(root_mass, (0, 0, 0), ((0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1))) \
        if root_mass else None
    return build_model("pm.yaml", "pm", [Link("base", root), Link("bob", bob)],
                       [Joint("swing", JointType.REVOLUTE, "base", "bob", axis=vec3([0, 1, 0]))])


def test_massless_root_with_mass_on_a_line_is_refused():
    with pytest.raises(InvalidInertiaError, match="singular"):
        floating.add_floating_base(_point_mass_robot(0))
    assert floating.add_floating_base(_point_mass_robot(2.0)).dof == 7
    with pytest.raises(InvalidInertiaError, match="no mass"):
        floating.add_floating_base(build_model("e.yaml", "e", [Link("a"), Link("b")], [
            Joint("j", JointType.REVOLUTE, "a", "b")]))


def test_root_named_world_cannot_float():
    robot = build_model("w.urdf", "w", [Link("world"), Link("b", Inertial(1.0))],
                        [Joint("j", JointType.REVOLUTE, "world", "b")])
    with pytest.raises(KinematicTreeError, match="world"):
        floating.add_floating_base(robot)


def test_scene_floating_errors_name_the_scene():
    with pytest.raises(SceneError, match=r"^pm_scene.yaml: floating_base: floating base 'base'"):
        apply_scene(_point_mass_robot(0),
                    load_scene("pm_scene.yaml", text="version: 1\nfloating_base: true"))
    for text, element in (("floating_base: true\nfixed_base: true", "floating_base"),
                          ("floating_base: true\nbase: bob", "base"),
                          ("floating_base: 1", "floating_base")):
        with pytest.raises(SceneError, match=f"^s.yaml: {element}: "):
            load_scene("s.yaml", text="version: 1\n" + text)


def test_base_floating_is_short_for_floating_base():
    scene = load_scene("s.yaml", text="version: 1\nbase: floating")
    assert scene.floating_base and scene.base is None
    reduced, _ = apply_scene(_point_mass_robot(2.0), scene)
    assert reduced.free_flyer and (reduced.nq, reduced.dof) == (8, 7)
    with pytest.raises(SceneError, match="^s.yaml: base: 'base: floating' contradicts"):
        load_scene("s.yaml", text="version: 1\nbase: floating\nfloating_base: false")


def test_small_floating_robot_symbolic_matches_numeric():
    """derive() on a floating model, against eomgen's Newton–Euler (exact structure check of
    the virtual joints with a symbolic-sized model)."""
    from eomgen.symbolic.evaluate import compile_program

    model = floating.add_floating_base(_point_mass_robot(2.0))
    dyn = eomgen.derive(model)
    f = compile_program(dyn.program, dyn.q + dyn.qd)
    nm = numeric.numeric_model(model)
    for q, qd in floating_states(7, 3, seed=6):
        out = f(*q, *qd)
        assert relative(out["M"], numeric.M_rnea(nm, q)) <= 1e-12
        assert relative(out["C"] @ qd, numeric.coriolis_times_qd(nm, q, qd)) <= 1e-12
        assert relative(out["g"].ravel(), numeric.gravity_torques(nm, q)) <= 1e-12


def test_scene_floating_base_takes_its_chart():
    for text, chart in (("true", "quaternion"), ("euler", "euler"), ("quaternion", "quaternion"),
                        ("false", False)):
        assert load_scene("s.yaml", text=f"version: 1\nfloating_base: {text}").floating_base \
            == chart
    for text in ("[1]", "quaternions", "1"):
        with pytest.raises(SceneError, match="^s.yaml: floating_base: expected true, false, "
                                             "'euler' or 'quaternion'"):
            load_scene("s.yaml", text=f"version: 1\nfloating_base: {text}")


def _numeric_total(model):
    """Mass, first moment and rotational inertia about the root origin of ``model`` at q = 0,
    from the numeric model's forward kinematics (eomgen.numeric, float arrays)."""
    nm = numeric.numeric_model(model)
    poses = numeric.link_poses(nm, np.zeros(nm.n))
    mass, h, I_O = 0.0, np.zeros(3), np.zeros((3, 3))
    for i, name in enumerate(nm.body_names):
        R, p = poses[name]
        c = p + R @ nm.com[i]
        mass += nm.mass[i]
        h += nm.mass[i] * c
        I_O += R @ nm.inertia[i] @ R.T + nm.mass[i] * (c @ c * np.eye(3) - np.outer(c, c))
    return mass, h, I_O


def _bundled(name, couple_offset=None):
    model = eomgen.load(eomgen.example_path(name))
    if couple_offset is not None:  # the second joint follows the first, at an offset
        from eomgen.model import couple
        first, second = model.joint_names[:2]
        model = couple(model, second, first, ratio=-0.5, offset=couple_offset)
    return model.with_numeric_parameters()


@pytest.mark.parametrize("robot", ["puma560_arm3", "scara_rrp", "stanford_rrp", "elbow_rrr",
                                   "elbow_rrr coupled", "point mass", "solo12"])
def test_total_inertia_at_zero_is_the_numeric_models(robot):
    """The model layer's total spatial inertia (what check_spatial_inertia refuses on) equals
    the one of the numeric model's link poses at q = 0: total mass, centre of mass, rotational
    inertia; a coupled joint sits at its offset."""
    if robot == "solo12":
        robots = erd_robots_dir()
        if robots is None:
            pytest.skip("example-robot-data is not installed")
        model = load_quietly(robots / SOLO)
    elif robot == "point mass":
        model = _point_mass_robot(2.0)
    else:
        model = _bundled(robot.split()[0], 0.7 if "coupled" in robot else None)
    total = floating.total_inertial(model)
    mass, h, I_O = _numeric_total(model)
    assert abs(float(total.mass) - mass) <= 1e-12 * mass
    assert np.allclose([float(x) for x in total.first_moment], h, rtol=1e-12, atol=1e-12 * mass)
    assert np.allclose(np.array(total.inertia, dtype=float), I_O, rtol=1e-12,
                       atol=1e-12 * np.abs(I_O).max())
    if robot == "elbow_rrr coupled":  # the offset moves mass: not the uncoupled pose
        from eomgen.model import uncoupled
        assert not np.allclose(_numeric_total(uncoupled(model))[2], I_O)


def test_parameters_without_values_are_not_checked_here():
    """A robot whose masses are symbols without values floats (checked when they get values),
    as before; the same robot with a value of zero mass is refused."""
    import sympy as sp
    from eomgen.model import Parameter
    m = sp.Symbol("m")
    links = [Link("a"), Link("b", Inertial(m, (0, 0, -0.5)))]
    joints = [Joint("j", JointType.REVOLUTE, "a", "b")]
    free = build_model("s.yaml", "s", links, joints, parameters=[Parameter(m, None)])
    assert floating.add_floating_base(free).dof == 7
    zero = build_model("s.yaml", "s", links, joints, parameters=[Parameter(m, 0.0)])
    with pytest.raises(InvalidInertiaError, match="no mass"):
        floating.add_floating_base(zero)
