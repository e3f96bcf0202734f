"""Contacts (eomgen.numeric.contacts, scene ``contacts``): KKT constrained dynamics and its checks.

References: Pinocchio's ``constraintDynamics`` with ``RigidConstraintModel`` (CONTACT_3D in
LOCAL_WORLD_ALIGNED, CONTACT_6D in LOCAL) on the free-flyer solo12 from its own URDF reader;
statics of solo12 standing (Pinocchio's total mass and centre of mass); the closed form of a
planar 2-link arm pressing on a wall (docs/contact.md); energy conservation of a top spinning
on a point.
"""

from __future__ import annotations


import numpy as np
import pytest

import eomgen
from support import (
    CONTACTS, DOCS, erd_robots_dir, floating_states, load_quietly, relative, run_in_process,
)
from eomgen import numeric
from eomgen.model import floating
from eomgen.numeric import floating_base
from eomgen.numeric.contacts import Contact, ContactDynamics, derived_mass_and_bias
from eomgen.errors import SceneError
from eomgen.model.floating import add_free_flyer
from eomgen.model import Inertial, Joint, JointType, Link, Transform, build_model
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support.robots import SOLO, FreeFlyerReference
from support.reference import pinocchio_contacts
from support.extras import need

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


@pytest.fixture(scope="module")
def solo():
    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    path = erd_robots_dir() / SOLO
    return path, floating.add_floating_base(load_quietly(path))


@pytest.mark.parametrize("kind, feet", [("point", FEET), ("surface", FEET[:1])])
def test_constrained_dynamics_matches_pinocchio(solo, kind, feet):
    pin = need("pinocchio", reason="Pinocchio is the reference")
    path, model = solo
    cd = ContactDynamics(model, tuple(Contact(f, kind) for f in feet))
    ref = FreeFlyerReference(path, model.joint_names)
    pm, pd, idx = ref.model, ref.data, ref.idx
    models, datas = pinocchio_contacts(pm, pd, feet, kind)
    rng = np.random.default_rng(20)
    for q, qd in floating_states(18, 2, seed=21):
        tau = rng.uniform(-2, 2, 18)
        qdd, F = cd.constrained_forward_dynamics(q, qd, tau)
        q_pin, v = ref.state(q, qd)
        T = floating_base.velocity_map(q)
        tau_pin = np.linalg.solve(T.T, tau)  # generalised forces map by Tᵀ
        a = pin.constraintDynamics(pm, pd, q_pin, v, tau_pin[idx], models, datas,
                                   pin.ProximalSettings(1e-14, 1e-12, 1))
        a_ours = np.empty(18)
        a_ours[idx] = a
        qdd_pin = np.linalg.solve(T, a_ours - floating_base.velocity_map_dot_qd(q, qd))
        assert relative(qdd, qdd_pin) <= 1e-8
        assert relative(F, pd.lambda_c) <= 1e-8
        # the contact inverse dynamics gives back τ
        assert relative(cd.inverse_dynamics(q, qd, qdd, F), tau) <= 1e-10


def test_contact_jacobian_is_a_finite_difference_of_frame_positions(solo):
    _, model = solo
    cd = ContactDynamics(model, tuple(Contact(f) for f in FEET))
    nm = numeric.numeric_model(model)
    q, qd = next(floating_states(18, 1, seed=22))
    h = 1e-6
    plus, minus = numeric.link_poses(nm, q + h * qd), numeric.link_poses(nm, q - h * qd)
    fd = np.concatenate([(plus[f][1] - minus[f][1]) / (2 * h) for f in FEET])
    assert np.allclose(cd.contact_jacobian(q) @ qd, fd, atol=1e-8)
    Jdot = (cd.contact_jacobian(q + h * qd) - cd.contact_jacobian(q - h * qd)) / (2 * h)
    assert np.allclose(cd.contact_bias(q, qd), Jdot @ qd, atol=1e-7)


def _standing(model):
    q = np.zeros(18)
    q[2] = 0.3
    for k, leg in enumerate(("FL", "FR", "HL", "HR")):
        front = leg[0] == "F"
        q[model.joint_names.index(f"{leg}_HFE")] = 0.8 if front else -0.8
        q[model.joint_names.index(f"{leg}_KFE")] = -1.6 if front else 1.6
    return q


def test_solo12_standing_statics(solo):
    pin = need("pinocchio", reason="Pinocchio gives mass and centre of mass")
    path, model = solo
    cd = ContactDynamics(model, tuple(Contact(f, mu=0.7) for f in FEET))
    q = _standing(model)
    zero = np.zeros(18)
    g = numeric.gravity_torques(numeric.numeric_model(model), q)
    J = cd.contact_jacobian(q)
    # the unactuated base: g_base = J_baseᵀ F (least-norm F); the joints hold the rest
    F = np.linalg.lstsq(J[:, :6].T, g[:6], rcond=None)[0]
    tau = g - J.T @ F
    assert np.allclose(tau[:6], 0, atol=1e-10)
    ref = FreeFlyerReference(path, model.joint_names)
    q_pin, _ = ref.state(q, zero)
    mass = pin.computeTotalMass(ref.model)
    com = pin.centerOfMass(ref.model, ref.data, q_pin)
    forces = F.reshape(4, 3)
    feet = [cd._kinematics(q, zero)[f]["p"] for f in FEET]
    assert all(p[2] < q[2] - 0.1 for p in feet)                     # feet below the trunk
    assert np.allclose(forces.sum(axis=0), [0, 0, mass * 9.81], rtol=1e-10, atol=1e-9)
    moment = sum(np.cross(p - com, f) for p, f in zip(feet, forces))
    assert np.allclose(moment, 0, atol=1e-9)
    assert all(inside for inside, _ in cd.friction_cone(F))
    # forward: those torques hold the robot still, with those contact forces
    qdd, F2 = cd.constrained_forward_dynamics(q, zero, tau)
    assert np.abs(qdd).max() < 1e-9
    assert relative(F2, F) <= 1e-9


def test_friction_cone():
    cd = ContactDynamics(None, (Contact("a", mu=0.5), Contact("b", "surface", mu=1.0),
                                Contact("c")))
    result = cd.friction_cone([1, 0, 2] + [0.5, 0, 1, 9, 9, 9] + [5, 0, -1])
    assert result[0] == (True, 0.0)
    assert result[1][0] and np.isclose(result[1][1], 0.5)
    assert result[2] == (True, float("inf"))
    outside = cd.friction_cone([1.1, 0, 2] + [0, 0, -1, 0, 0, 0] + [0, 0, 1])
    assert not outside[0][0] and not outside[1][0]


def test_two_link_arm_pressing_on_a_wall():
    """Closed form (docs/contact.md): the tip of the planar arm pushes on a wall normal to x
    with force f; the wall's force on the arm is (−f, 0, 0), and the static torques are
    τ = g(q) + f (−l1 s1 − l2 s12, −l2 s12)."""
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    values = {s.name: v for s, v in arm.parameter_values.items()}
    m1, m2, l1, l2, lc1, lc2, g0 = (values[k] for k in ("m1", "m2", "l1", "l2", "lc1",
                                                         "lc2", "g"))
    cd = ContactDynamics(arm, (Contact("tip", normal=(-1.0, 0.0, 0.0)),))
    q1, q2, f = 0.4, 0.9, 3.0
    s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
    gq = [(m1 * lc1 + m2 * l1) * g0 * c1 + m2 * lc2 * g0 * c12, m2 * lc2 * g0 * c12]
    tau = np.array(gq) + f * np.array([-l1 * s1 - l2 * s12, -l2 * s12])
    F = np.array([-f, 0.0, 0.0])
    zero = np.zeros(2)
    assert np.allclose(cd.inverse_dynamics([q1, q2], zero, zero, F), tau, atol=1e-12)
    # a planar arm cannot push out of its plane: the z row of J_c is zero, the KKT matrix
    # singular, and the damped variant gives the in-plane forces
    with pytest.raises(np.linalg.LinAlgError):
        cd.constrained_forward_dynamics([q1, q2], zero, tau)
    qdd, F2 = cd.constrained_forward_dynamics([q1, q2], zero, tau, damping=1e-12)
    assert np.abs(qdd).max() < 1e-9 and np.allclose(F2, F, atol=1e-8)
    assert cd.friction_cone(F2)[0] == (True, float("inf"))  # no μ given


def _top():
    """A box on a free base, spinning on the point 'tip' 0.3 m below its centre of mass."""
    box = Inertial(2.0, (0, 0, 0), ((0.03, 0, 0), (0, 0.03, 0), (0, 0, 0.05)))
    robot = build_model("top.yaml", "top", [Link("box", box), Link("tip")],
                        [Joint("peg", JointType.FIXED, "box", "tip",
                               Transform.from_xyz_rpy((0, 0, -0.3)))])
    return floating.add_floating_base(robot)


def test_energy_is_conserved_with_contacts_and_no_torque():
    model = _top()
    cd = ContactDynamics(model, (Contact("tip"),), mass_and_bias=derived_mass_and_bias(model))
    nm = numeric.numeric_model(model)
    q = np.array([0, 0, 0, 0.2, 0.3, -0.1])
    q[:3] = -cd._kinematics(q, np.zeros(6))["tip"]["p"]  # put the tip at the origin
    J = cd.contact_jacobian(q)
    null = np.linalg.svd(J)[2][3:]
    qd = null.T @ np.array([0.5, -0.3, 8.0])  # a velocity the contact allows (J q̇ = 0)

    M, h = cd.mass_and_bias(q, qd)  # the derived program, checked against Newton–Euler
    assert relative(M, numeric.M_rnea(nm, q)) <= 1e-12
    assert relative(h, numeric.rnea(nm, q, qd, np.zeros(6))) <= 1e-12

    def energy(q, qd):
        return numeric.kinetic_energy(nm, q, qd) + numeric.potential_energy(nm, q)

    def f(x):
        qdd, _ = cd.constrained_forward_dynamics(x[:6], x[6:], np.zeros(6))
        return np.concatenate([x[6:], qdd])

    x, dt = np.concatenate([q, qd]), 2e-3
    E0 = energy(q, qd)
    for _ in range(150):  # RK4
        k1 = f(x)
        k2 = f(x + dt / 2 * k1)
        k3 = f(x + dt / 2 * k2)
        k4 = f(x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    assert abs(energy(x[:6], x[6:]) - E0) <= 1e-7 * abs(E0)
    assert np.linalg.norm(cd._kinematics(x[:6], x[6:])["tip"]["p"]) < 1e-8  # still on it
    assert abs(x[4] - q[4]) > 1e-3 or abs(x[3] - q[3]) > 1e-2  # it did move


def test_redundant_contacts_need_the_damped_variant(solo):
    _, model = solo
    cd = ContactDynamics(model, (Contact("FL_FOOT"), Contact("FL_FOOT", name="again")))
    q, qd = next(floating_states(18, 1, seed=23))
    tau = np.zeros(18)
    with pytest.raises(np.linalg.LinAlgError):
        cd.constrained_forward_dynamics(q, qd, tau)
    qdd, F = cd.constrained_forward_dynamics(q, qd, tau, damping=1e-9)
    single = ContactDynamics(model, (Contact("FL_FOOT"),))
    qdd1, F1 = single.constrained_forward_dynamics(q, qd, tau)
    assert np.allclose(F[:3], F[3:]) and np.allclose(F[:3] + F[3:], F1, rtol=1e-6)
    assert np.allclose(qdd, qdd1, rtol=1e-6, atol=1e-6)


def test_baumgarte_velocity_gain_damps_a_drifting_contact(solo):
    """With J q̇ ≠ 0, kd makes the constraint accelerate against it: J q̈ + J̇ q̇ = −kd J q̇."""
    _, model = solo
    q, qd = next(floating_states(18, 1, seed=24))
    cd = ContactDynamics(model, (Contact("FL_FOOT", kd=10.0),))
    qdd, _ = cd.constrained_forward_dynamics(q, qd, np.zeros(18))
    J = cd.contact_jacobian(q)
    assert np.allclose(J @ qdd + cd.contact_bias(q, qd), -10.0 * J @ qd, atol=1e-8)


def test_baumgarte_position_gain_pulls_a_point_contact_to_its_anchor(solo):
    _, model = solo
    q, qd = next(floating_states(18, 1, seed=26))
    anchor = np.array([0.1, -0.2, 0.0])
    cd = ContactDynamics(model, (Contact("FL_FOOT", kp=25.0, kd=10.0),),
                         anchors={"FL_FOOT": anchor})
    qdd, _ = cd.constrained_forward_dynamics(q, qd, np.zeros(18))
    J = cd.contact_jacobian(q)
    error = cd._kinematics(q, qd)["FL_FOOT"]["p"] - anchor
    assert np.allclose(J @ qdd + cd.contact_bias(q, qd), -10.0 * J @ qd - 25.0 * error,
                       atol=1e-8)


def test_contacts_made_in_python_are_checked():
    for kwargs, match in (({"kind": "line"}, "kind"), ({"mu": -0.1}, "negative"),
                          ({"kd": -1.0}, "non-negative")):
        with pytest.raises(ValueError, match=match):
            Contact("FL_FOOT", **kwargs)


def test_scene_contacts_through_apply_scene(solo):
    path, model = solo
    robot = load_quietly(path)
    scene = load_scene("solo.yaml", text="version: 1\nfloating_base: euler\ncontacts:\n"
                       + "".join(f"  - {{frame: {f}, mu: 0.7}}\n" for f in FEET))
    reduced, report = apply_scene(robot, scene)
    assert reduced.joint_names == model.joint_names
    assert [c.frame for c in report.contacts] == list(FEET)
    assert any(note.startswith("contacts") and "μ = 0.7" in note for note in report.notes)
    assert all(f in reduced.link_by_name for f in FEET)  # kept though merged into the shanks
    q, qd = next(floating_states(18, 1, seed=25))
    tau = np.ones(18)
    a = ContactDynamics(reduced, report.contacts).constrained_forward_dynamics(q, qd, tau)
    b = ContactDynamics(model, report.contacts).constrained_forward_dynamics(q, qd, tau)
    assert relative(a[0], b[0]) <= 1e-10 and relative(a[1], b[1]) <= 1e-10


def test_documented_contact_errors_are_what_eomgen_prints(solo):
    path, _ = solo
    robot = load_quietly(path)
    text = (DOCS / "scenes.md").read_text(encoding="utf-8")
    documented = [line[len("eomgen: error: "):] for line in text.splitlines()
                  if line.startswith("eomgen: error: solo_scene.yaml")]
    scenes = ["contacts: [{frame: FL_FOT}]", "contacts: [{frame: FL_FOOT, mu: -0.5}]",
              "base: FL_UPPER_LEG\ncontacts: [{frame: base_link}]"]
    printed = []
    for body in scenes:
        with pytest.raises(SceneError) as caught:
            apply_scene(robot, load_scene("solo_scene.yaml", text="version: 1\n" + body))
        printed.append(str(caught.value))
    bob = Inertial(1.0, (0, 0, -0.5))
    pendulum = build_model("p.yaml", "p", [Link("base"), Link("bob", bob)],
                           [Joint("swing", JointType.REVOLUTE, "base", "bob")])
    with pytest.raises(SceneError) as caught:
        apply_scene(pendulum, load_scene("solo_scene.yaml",
                                         text="version: 1\nfloating_base: true"))
    printed.append(str(caught.value))
    assert printed == documented
    for line in printed:
        assert "\n" not in line


def test_cli_refuses_a_bad_contact_with_one_line_and_exit_code_2(solo, tmp_path):
    path, _ = solo
    scene = tmp_path / "solo_scene.yaml"
    scene.write_text("version: 1\nfloating_base: true\ncontacts: [{frame: FL_FOOT, mu: -0.5}]\n")
    result = run_in_process("generate", path, "--scene", scene, "-o", tmp_path / "out")
    assert result.returncode == 2
    assert result.stderr.strip() == (f"eomgen: error: {scene}: contacts[0] 'FL_FOOT' mu: "
                                     "friction coefficient -0.5 is negative (μ ≥ 0)")
    assert not (tmp_path / "out").exists()


def test_example_contact_scene(solo):
    path, model = solo
    scene = load_scene(CONTACTS
                       / "solo12_standing.yaml")
    reduced, report = apply_scene(load_quietly(path), scene)
    # floating_base: true is Pinocchio's free flyer: its q and v, joints in its order
    flyer = add_free_flyer(load_quietly(path))
    assert scene.robot == "solo" and reduced.joint_names == flyer.joint_names
    assert (reduced.nq, reduced.dof) == (19, 18)
    assert [(c.frame, c.kind, c.mu) for c in report.contacts] == [(f, "point", 0.7)
                                                                 for f in FEET]


def test_documented_contact_scene_loads(solo):
    path, model = solo
    text = (DOCS / "scenes.md").read_text(encoding="utf-8")
    block = [b for b in text.split("```yaml\n")[1:] if "robot: solo" in b][0].split("```")[0]
    reduced, report = apply_scene(load_quietly(path), load_scene("doc.yaml", text=block))
    flyer = add_free_flyer(load_quietly(path))  # floating_base: true, the quaternion chart
    assert reduced.joint_names == flyer.joint_names and len(report.contacts) == 4
