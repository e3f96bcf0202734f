"""Actuators and flexible joints (eomgen.analysis.actuators, docs/actuators.md).

References: MuJoCo (``qM``, ``qfrc_bias``, ``qfrc_passive`` with ``armature`` and ``damping``
set on the same URDF) for the rigid model with actuators; eomgen's numeric Newton–Euler for
the link torques and their time derivatives (finite differences in time); energy conservation
and the limit K → ∞ for Spong's model; flatness fed back to forward dynamics.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.analysis import actuators as A
from eomgen.errors import InvalidActuatorError, SceneError, SchemaError
from eomgen.model import Actuator
from eomgen.numeric import numeric_model, rnea
from eomgen.parsers.urdf import parse_urdf_string
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene

from support import ROOT, erd_robots_dir
from support.extras import need

FLEXIBLE_2LINK = ROOT / "examples" / "robots" / "flexible_2link.yaml"

ARM = """<robot name="r"><link name="base"/>
<link name="arm"><inertial><mass value="2"/><origin xyz="0.3 0 0"/>
<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
<link name="tool"/>
<joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
{dynamics}</joint>
<joint name="j2" type="fixed"><parent link="arm"/><child link="tool"/>
<dynamics damping="9"/></joint></robot>"""


# ----------------------------------------------------------------------------------------------
# Reading actuator data
# ----------------------------------------------------------------------------------------------

def test_urdf_dynamics_is_read_as_damping_and_coulomb_friction():
    model = parse_urdf_string(ARM.format(dynamics='<dynamics damping="0.5" friction="0.25"/>'))
    a = model.joints[0].actuator
    assert (float(a.damping), float(a.friction), a.armature, a.flexible) == (0.5, 0.25, 0, False)
    assert model.joints[1].actuator is None  # a fixed joint's <dynamics> couples nothing
    zero = parse_urdf_string(ARM.format(dynamics='<dynamics damping="0" friction="0.0"/>'))
    assert zero.joints[0].actuator is None


def test_yaml_rotor_and_gear_give_the_reflected_inertia_and_stay_symbolic():
    arm = eomgen.load(FLEXIBLE_2LINK)
    B1, K1 = sp.Symbol("B1", real=True), sp.Symbol("K1", real=True)
    assert arm.movable_joints[0].actuator == Actuator(armature=B1, stiffness=K1)
    assert {"B1", "K1"} <= {p.name for p in arm.parameters}
    scene = load_scene("s.yaml", text="version: 1\nactuators:\n  joint2: {rotor_inertia: 2.0e-4, "
                       "gear_ratio: 50, damping: 0.1}\n")
    a = apply_scene(arm, scene).model.movable_joints[1].actuator
    assert float(a.armature) == pytest.approx(50 ** 2 * 2.0e-4, rel=1e-15)
    assert (float(a.gear_ratio), float(a.damping), a.stiffness.name) == (50, 0.1, "K2")


@pytest.mark.parametrize("text, element, problem", [
    ("actuators: {joint2: {stiffness: -3}}", "actuators 'joint2'", "stiffness -3 is negative"),
    ("actuators: {joint2: {armature: 0}}", "actuators 'joint2'",
     "zero motor inertia on a flexible joint"),
    ("actuators: {joint2: {rotor_inertia: 1.0e-4, gear_ratio: 0}}", "actuators 'joint2'",
     "gear_ratio is 0"),
    ("actuators: {joint9: {damping: 1}}", "actuators 'joint9'", "no joint 'joint9'"),
    ("actuators: {tip_fixed: {damping: 1}}", "actuators 'tip_fixed'", "fixed joint"),
    ("actuators: {joint2: {armature: 1, gear_ratio: 3}}", "actuators 'joint2'", "not both"),
    ("friction: {joint2: 0.1}", "friction", "under 'actuators'"),
    ("actuators: {joint2: {gear_ratio: 100}}", "actuators 'joint2'",
     "'gear_ratio' given without 'rotor_inertia'"),
])
def test_bad_scene_actuators_are_one_line_naming_the_scene_and_the_joint(text, element, problem):
    arm = eomgen.load(FLEXIBLE_2LINK)
    with pytest.raises(SceneError) as caught:
        apply_scene(arm, load_scene("bad.yaml", text="version: 1\n" + text + "\n"))
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"bad.yaml: {element}: "), message
    assert problem in message
    # drive values that are not physical are InvalidActuatorErrors in a scene too
    assert isinstance(caught.value, InvalidActuatorError) == any(
        p in problem for p in ("stiffness", "motor inertia", "gear_ratio is 0"))


# ----------------------------------------------------------------------------------------------
# Rigid model with actuators: against MuJoCo
# ----------------------------------------------------------------------------------------------

def _mujoco_model(urdf: Path, armature: dict, damping: dict):
    """MuJoCo's model of the URDF (visual and collision geometry removed: MuJoCo would load
    the meshes) with the given armature and damping per joint."""
    mujoco = need("mujoco", reason="MuJoCo is the reference")
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", urdf.read_text(), flags=re.S)
    m = mujoco.MjSpec.from_string(text).compile()
    for name in armature:  # runtime model fields, read by mj_crb (qM) and mj_passive
        m.dof_armature[m.joint(name).dofadr[0]] = armature[name]
        m.dof_damping[m.joint(name).dofadr[0]] = damping[name]
    return mujoco, m


@pytest.mark.parametrize("robot, scene_head", [
    ("ur_description/urdf/ur5_robot.urdf", "version: 1\n"),
    ("panda_description/urdf/panda.urdf", "version: 1\n"),
])
def test_mass_matrix_bias_and_damping_match_mujoco(robot, scene_head):
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    urdf = robots / robot
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the Panda's mimic fingers: independent in both
        model = eomgen.load(urdf, couplings=False)
    names = model.joint_names
    rng = np.random.default_rng(7)
    armature = {n: float(v) for n, v in zip(names, rng.uniform(0.05, 0.5, len(names)))}
    damping = {n: float(v) for n, v in zip(names, rng.uniform(0.1, 2.0, len(names)))}
    scene = load_scene("s.yaml", text=scene_head + "actuators:\n" + "".join(
        f"  {n}: {{armature: {armature[n]!r}, damping: {damping[n]!r}}}\n" for n in names))
    model = apply_scene(model, scene).model  # fixed joints merged, as MuJoCo's fusestatic
    assert model.joint_names == names
    am = A.actuated_model(eomgen.derive(model))
    mujoco, m = _mujoco_model(urdf, armature, damping)
    data = mujoco.MjData(m)
    qadr = [m.joint(n).qposadr[0] for n in names]
    vadr = [m.joint(n).dofadr[0] for n in names]
    for _ in range(3):
        q, qd = rng.uniform(-2, 2, len(names)), rng.uniform(-2, 2, len(names))
        data.qpos[qadr], data.qvel[vadr] = q, qd
        mujoco.mj_forward(m, data)
        full = np.zeros((m.nv, m.nv))
        try:
            mujoco.mj_fullM(m, data, full)  # MuJoCo ≥ 3.3 (sparse data.M)
        except TypeError:
            mujoco.mj_fullM(m, full, data.qM)
        M_ref = full[np.ix_(vadr, vadr)]
        M, h, _ = am.rigid_terms(q, qd)
        M_a = A.rigid_M(am, q)
        assert np.abs(M_a - M_ref).max() <= 1e-10 * np.abs(M_ref).max()
        assert np.allclose(M_a - M, np.diag([armature[n] for n in names]), rtol=0, atol=1e-14)
        bias = data.qfrc_bias[vadr]
        assert np.abs(h - bias).max() <= 1e-10 * np.abs(bias).max()
        passive = data.qfrc_passive[vadr]  # −d q̇: the torque friction applies to the joint
        tau_f = A.friction_torque(am, qd)
        assert np.abs(tau_f + passive).max() <= 1e-12 * np.abs(passive).max()


def test_mujoco_reads_the_same_urdf_damping_as_eomgen():
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    urdf = robots / "panda_description/urdf/panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(urdf, couplings=False)  # MuJoCo reads every joint
    mujoco, m = _mujoco_model(urdf, {}, {})
    ours = [float(j.actuator.damping) if j.actuator else 0.0 for j in model.movable_joints]
    theirs = [float(m.dof_damping[m.joint(n).dofadr[0]]) for n in model.joint_names]
    assert ours == theirs and 0.003 in ours and 0.3 in ours


def test_symbolic_rigid_model_adds_the_armature_and_friction():
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    acts = (Actuator(armature=0.2, damping=0.3, friction=0.5, friction_width=0.05),
            Actuator.from_rotor(1e-4, 60, damping=0.1))
    it = iter(acts)
    arm = replace(arm, joints=tuple(replace(j, actuator=next(it)) if j.type.is_movable else j
                                    for j in arm.joints))
    rigid = A.rigid_with_actuators(eomgen.derive(arm))
    nm = numeric_model(arm)
    q, qd, qdd = np.array([0.3, -0.7]), np.array([0.4, -1.1]), np.array([1.5, 0.2])
    values = dict(zip(rigid.dynamics.q, q)) | dict(zip(rigid.dynamics.qd, qd)) \
        | dict(zip(rigid.dynamics.qdd, qdd)) | arm.parameter_values
    armature = np.array([0.2, 60 ** 2 * 1e-4])
    friction = np.array([0.3 * 0.4 + 0.5, 0.1 * -1.1])
    expected = rnea(nm, q, qd, qdd) + armature * qdd + friction
    exact = np.array(rigid.tau().xreplace(values).evalf(), float).ravel()
    assert np.allclose(exact, expected, rtol=1e-12, atol=0)
    smooth = np.array(rigid.tau(smooth=True).xreplace(values).evalf(), float).ravel()
    assert smooth[0] - exact[0] == pytest.approx(0.5 * (np.tanh(0.4 / 0.05) - 1), rel=1e-12)
    am = A.actuated_model(rigid.dynamics)
    assert np.allclose(A.rigid_inverse_dynamics(am, q, qd, qdd), expected, rtol=1e-12)
    qdd_back = A.rigid_forward_dynamics(am, q, qd, expected, smooth=False)
    assert np.allclose(qdd_back, qdd, rtol=1e-10)


# ----------------------------------------------------------------------------------------------
# Spong's model
# ----------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def flexible_arm():
    dyn = eomgen.derive(eomgen.load(FLEXIBLE_2LINK))
    return dyn, A.actuated_model(dyn)


def _integrate(am, x0, tau, duration, rtol=1e-11, atol=1e-11, method="DOP853"):
    from scipy.integrate import solve_ivp

    return solve_ivp(lambda t, x: A.flexible_forward_dynamics(am, x, tau(t)), (0, duration),
                     x0, method=method, rtol=rtol, atol=atol, dense_output=True)


def test_energy_is_conserved_without_friction_and_input(flexible_arm):
    _, am = flexible_arm
    x0 = np.array([0.4, -0.6, 0.0, 0.0, 0.45, -0.5, 1.0, -2.0])  # springs wound, motors moving
    result = _integrate(am, x0, lambda t: np.zeros(2), 2.0)
    assert result.success
    energy = [A.flexible_energy(am, x) for x in result.y.T]
    scale = max(abs(e) for e in energy)
    assert np.ptp(energy) <= 1e-8 * scale
    # the spring exchanges energy: the motor angles do move away from their start
    assert np.ptp(result.y[4]) > 0.05


def test_symbolic_equations_vanish_along_numeric_forward_dynamics(flexible_arm):
    dyn, am = flexible_arm
    sd = A.spong_dynamics(dyn)
    rng = np.random.default_rng(3)
    x, tau = rng.normal(size=8), rng.normal(size=2)
    xd = A.flexible_forward_dynamics(am, x, tau)
    values = dict(zip(dyn.q, x[:2])) | dict(zip(dyn.qd, x[2:4])) | dict(zip(sd.theta, x[4:6])) \
        | dict(zip(sd.thetad, x[6:])) | dict(zip(dyn.qdd, xd[2:4])) \
        | dict(zip(sd.thetadd, xd[6:])) | dict(zip(sd.tau, tau)) | dyn.model.parameter_values
    link = np.array(sd.link_equations().xreplace(values).evalf(), float)
    motor = np.array(sd.motor_equations().xreplace(values).evalf(), float)
    assert np.abs(link).max() < 1e-10 and np.abs(motor).max() < 1e-10
    energy = float(sd.energy().xreplace(values))
    assert energy == pytest.approx(A.flexible_energy(am, x), rel=1e-12)


def test_stiff_limit_is_the_rigid_model_with_reflected_inertia():
    arm = eomgen.load(FLEXIBLE_2LINK)
    rigid = A.actuated_model(eomgen.derive(arm))
    q0, tau = np.array([0.3, 0.5]), lambda t: np.array([2.0, -1.0])
    from scipy.integrate import solve_ivp

    ref = solve_ivp(lambda t, x: np.concatenate(
        [x[2:], A.rigid_forward_dynamics(rigid, x[:2], x[2:], tau(t))]), (0, 0.5),
        np.concatenate([q0, [0, 0]]), method="DOP853", rtol=1e-11, atol=1e-11)
    errors = []
    for K in (1e3, 1e4, 1e5):
        am = A.actuated_model(eomgen.derive(arm), {"K1": K, "K2": K})
        x0 = A.flexible_rest_state(am, q0)  # the springs start wound for gravity
        result = _integrate(am, x0, tau, 0.5, rtol=1e-10, atol=1e-10)
        errors.append(np.abs(result.y[:2, -1] - ref.y[:2, -1]).max())
    # the link angles approach the rigid model's as 1/K (one decade per decade)
    assert errors[2] < errors[1] < errors[0]
    assert errors[0] / errors[2] > 30 and errors[2] < 1e-3


def _trajectory(t):
    """q(t) = a sin(ω t + φ) and its derivatives up to order 4."""
    a, w, phi = np.array([0.5, -0.8]), np.array([2.0, 3.0]), np.array([0.2, 1.0])
    s, c = np.sin(w * t + phi), np.cos(w * t + phi)
    return a * s, a * w * c, -a * w ** 2 * s, -a * w ** 3 * c, a * w ** 4 * s


def test_link_torque_derivatives_match_finite_differences_of_newton_euler(flexible_arm):
    dyn, am = flexible_arm
    nm = numeric_model(dyn.model)
    t, h = 0.37, 1e-3
    tau, taud, taudd = am.link_torque_derivatives(*_trajectory(t))
    L = [rnea(nm, *_trajectory(t + k * h)[:3]) for k in (-2, -1, 0, 1, 2)]
    assert np.allclose(tau, L[2], rtol=1e-13, atol=1e-12)
    fd1 = (L[0] - 8 * L[1] + 8 * L[3] - L[4]) / (12 * h)       # O(h⁴)
    fd2 = (-L[0] + 16 * L[1] - 30 * L[2] + 16 * L[3] - L[4]) / (12 * h * h)
    assert np.allclose(taud, fd1, rtol=1e-8, atol=1e-8)
    assert np.allclose(taudd, fd2, rtol=1e-5, atol=1e-5)


def test_flat_inverse_dynamics_fed_to_forward_dynamics_reproduces_the_trajectory(flexible_arm):
    _, am = flexible_arm
    flat = [A.flexible_inverse_dynamics(am, *_trajectory(t)) for t in (0.0,)]
    q0, qd0, *_ = _trajectory(0.0)
    x0 = np.concatenate([q0, qd0, flat[0]["theta"], flat[0]["thetad"]])
    result = _integrate(am, x0, lambda t: A.flexible_inverse_dynamics(
        am, *_trajectory(t))["tau"], 1.5)
    worst = max(np.abs(result.sol(t)[:2] - _trajectory(t)[0]).max()
                for t in np.linspace(0, 1.5, 16))
    assert worst < 1e-7


def test_symbolic_flat_inverse_dynamics_keeps_k_and_b_and_matches_numeric(flexible_arm):
    dyn, am = flexible_arm
    sd = A.spong_dynamics(dyn)
    flat = sd.flat_inverse_dynamics()
    assert {"K1", "K2", "B1", "B2"} <= {s.name for s in flat["tau"].free_symbols}
    q, qd, qdd, q3, q4 = _trajectory(0.8)
    values = dict(zip(dyn.q, q)) | dict(zip(dyn.qd, qd)) | dict(zip(dyn.qdd, qdd)) \
        | dict(zip(sd.qddd, q3)) | dict(zip(sd.qdddd, q4)) | dyn.model.parameter_values
    numeric = A.flexible_inverse_dynamics(am, q, qd, qdd, q3, q4)
    for name in ("theta", "thetadd", "tau"):
        exact = np.array(flat[name].xreplace(values).evalf(), float).ravel()
        assert np.allclose(exact, numeric[name], rtol=1e-11), name


def test_full_model_coupling_of_the_planar_arm_is_the_textbook_constant():
    # Planar 2R: rotor 2 rides on link 1 and spins about the same z axis, so the full model's
    # coupling is S = [[0, I_m2 r2], [0, 0]] (De Luca & Book, Springer Handbook, ch. 11).
    arm = eomgen.load(FLEXIBLE_2LINK)
    scene = load_scene("s.yaml", text="version: 1\nactuators:\n"
                       "  joint1: {rotor_inertia: 1.0e-4, gear_ratio: 70}\n"
                       "  joint2: {rotor_inertia: 2.0e-4, gear_ratio: 50}\n")
    sd = A.spong_dynamics(eomgen.derive(apply_scene(arm, scene).model), coupling=True)
    assert (sd.S[0, 0], sd.S[1, 0], sd.S[1, 1]) == (0, 0, 0)
    assert float(sd.S[0, 1]) == pytest.approx(2.0e-4 * 50, rel=1e-15)
    link, motor = sd.link_equations(), sd.motor_equations()
    assert sp.expand(motor[1]).coeff(sd.dynamics.qdd[0]) == sd.S[0, 1]   # S^T q̈
    assert sp.expand(link[0]).coeff(sd.thetadd[1]) == sd.S[0, 1]         # S θ̈
    assert sp.expand(motor[0]).coeff(sd.dynamics.qdd[1]) == 0
    with pytest.raises(eomgen.errors.ParameterError, match="rotor_inertia and gear_ratio"):
        A.spong_dynamics(eomgen.derive(arm), coupling=True)


def test_mixed_rigid_and_flexible_joints_with_friction_round_trip():
    # joint 1 rigid (armature, viscous and Coulomb friction), joint 2 flexible with motor
    # friction: the flat inputs (smoothed friction) drive forward dynamics along q(t)
    arm = eomgen.load(FLEXIBLE_2LINK)
    scene = load_scene("s.yaml", text="version: 1\nactuators:\n"
                       "  joint1: {armature: 0.3, damping: 0.4, friction: 0.2, "
                       "friction_width: 0.5}\n"
                       "  joint2: {damping: 0.05, friction: 0.1, friction_width: 0.5}\n")
    model = apply_scene(arm, scene).model
    a1 = model.movable_joints[0].actuator
    assert a1.flexible and float(a1.armature) == 0.3  # the description's K1 is kept
    joints = tuple(replace(j, actuator=replace(j.actuator, stiffness=None))
                   if j.name == "joint1" else j for j in model.joints)
    model = replace(model, joints=joints)
    am = A.actuated_model(eomgen.derive(model))
    assert am.flexible.tolist() == [1] and am.rigid.tolist() == [0]
    flat0 = A.flexible_inverse_dynamics(am, *_trajectory(0.0), smooth=True)
    q0, qd0, *_ = _trajectory(0.0)
    x0 = np.concatenate([q0, qd0, flat0["theta"], flat0["thetad"]])
    result = _integrate(am, x0, lambda t: A.flexible_inverse_dynamics(
        am, *_trajectory(t), smooth=True)["tau"], 1.0)
    worst = max(np.abs(result.sol(t)[:2] - _trajectory(t)[0]).max()
                for t in np.linspace(0, 1.0, 11))
    assert worst < 1e-7
    # the rigid joint's torque is the rigid model's: link torque + armature + friction
    q, qd, qdd, *_ = _trajectory(0.3)
    tau = A.flexible_inverse_dynamics(am, *_trajectory(0.3))["tau"]
    nm = numeric_model(model)
    expected = rnea(nm, q, qd, qdd)[0] + 0.3 * qdd[0] + 0.4 * qd[0] + 0.2 * np.sign(qd[0])
    assert tau[0] == pytest.approx(expected, rel=1e-12)


def test_rigid_actuator_program_prints_m_plus_armature(flexible_arm):
    from eomgen.symbolic.evaluate import compile_program

    dyn, am = flexible_arm
    rigid = A.rigid_with_actuators(dyn)
    params = [p.symbol for p in dyn.model.parameters]
    run = compile_program(rigid.program(), tuple(dyn.q) + tuple(dyn.qd) + tuple(params))
    q, qd = np.array([0.2, 1.1]), np.array([0.0, 0.0])
    out = run(*q, *qd, *[p.value for p in dyn.model.parameters])
    assert np.allclose(out["M"], A.rigid_M(am, q), rtol=1e-14)
    assert np.allclose(out["tau_f"], 0)


def test_scene_report_says_what_the_scene_set_and_which_joints_are_flexible():
    arm = eomgen.load(FLEXIBLE_2LINK)
    scene = load_scene("s.yaml", text="version: 1\nlocked: {joint2: 0.1}\nactuators:\n"
                       "  joint1: {damping: 0.2}\n  joint2: {damping: 0.3}\n")
    notes = apply_scene(arm, scene).report.notes
    assert "actuators set by the scene: joint1 (damping)" in notes
    assert "actuators of joints that do not move (no effect): joint2" in notes
    assert any(n.startswith("flexible joints") and n.endswith(": joint1") for n in notes)


SPATIAL_3R = """
name: spatial_3r
links:
  - name: base
  - {name: l1, mass: 1.0, com: [0, 0, 0.1], inertia: {ixx: 0.02, iyy: 0.03, izz: 0.01}}
  - {name: l2, mass: 0.8, com: [0.2, 0, 0], inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02}}
  - {name: l3, mass: 0.5, com: [0, 0.15, 0.05], inertia: {ixx: 0.01, iyy: 0.01, izz: 0.005}}
joints:
  - {name: j1, type: revolute, parent: base, child: l1, axis: [0, 0, 1],
     actuator: {rotor_inertia: 1.0e-4, gear_ratio: 50, stiffness: 200}}
  - {name: j2, type: revolute, parent: l1, child: l2, axis: [1, 0, 0],
     origin: {xyz: [0, 0, 0.2]}, actuator: {rotor_inertia: 2.0e-4, gear_ratio: 40, stiffness: 150}}
  - {name: j3, type: revolute, parent: l2, child: l3, axis: [0, 0, 1],
     origin: {xyz: [0.3, 0, 0]}, actuator: {rotor_inertia: 3.0e-4, gear_ratio: 30, stiffness: 100}}
"""


@pytest.mark.slow
def test_full_model_with_configuration_dependent_coupling_conserves_energy(tmp_path):
    # rotor 3 rides on link 2: its spin axis z3 = Rz(q1) Rx(q2) z, so S[0, 2] = I r cos q2
    # depends on q and the coupling's Ṡ and ∂S/∂q terms matter; energy conservation checks them
    from scipy.integrate import solve_ivp

    path = tmp_path / "spatial_3r.yaml"
    path.write_text(SPATIAL_3R, encoding="utf-8")
    # unsimplified: trigsimp of the 3-DOF expressions would dominate the test's time
    sd = A.spong_dynamics(eomgen.derive(eomgen.load(path), simplify=False), coupling=True)
    d = sd.dynamics
    q2 = d.q[1]
    coefficient = sd.S[0, 2] / sp.cos(q2)
    assert coefficient.is_number and float(coefficient) == pytest.approx(3.0e-4 * 30, rel=1e-14)
    assert sd.S[1, 2] == 0 and sd.S[0, 1] == 0  # joint 2 ⟂ joint 1; joint 3 ⟂ joint 2
    rhs = sd.forward_dynamics_function()
    states = list(d.q) + list(d.qd) + list(sd.theta) + list(sd.thetad)
    f_E = sp.lambdify(states, sd.energy().xreplace(d.model.parameter_values), "numpy")
    reduced = A.actuated_model(d)
    x = np.random.default_rng(5).normal(size=12)
    assert not np.allclose(rhs(x, np.zeros(3)), A.flexible_forward_dynamics(reduced, x,
                                                                             np.zeros(3)))
    plain = A.spong_dynamics(d).forward_dynamics_function()  # the reduced model, lambdified
    assert np.allclose(plain(x, [1, 2, 3]), A.flexible_forward_dynamics(reduced, x, [1, 2, 3]),
                       rtol=1e-10, atol=1e-10)
    x0 = np.array([0.1, 0.7, -0.4, 0.5, -1.0, 2.0, 0.12, 0.68, -0.38, 3.0, -2.0, 1.0])
    result = solve_ivp(lambda t, x: rhs(x, np.zeros(3)), (0, 0.5), x0, method="DOP853",
                       rtol=1e-11, atol=1e-11)
    energy = np.array([f_E(*x) for x in result.y.T])
    assert np.ptp(energy) <= 1e-8 * np.abs(energy).max()


@pytest.mark.parametrize("actuator, error, problem", [
    ({"gear_ratio": 100}, SchemaError, "'gear_ratio' given without 'rotor_inertia'"),
    ({"damping": -1}, InvalidActuatorError, "damping -1 is negative"),
    ({"friction": 1, "friction_width": 0}, InvalidActuatorError, "friction_width 0 is not"),
    ({"stiffnes": 1}, SchemaError, "did you mean 'stiffness'?"),
])
def test_bad_yaml_actuators_name_the_file_and_the_joint(actuator, error, problem):
    from eomgen.parsers.yaml_format import parse

    document = {"links": [{"name": "base"}, {"name": "arm", "mass": 1}],
                "joints": [{"name": "j1", "type": "revolute", "parent": "base", "child": "arm",
                            "actuator": actuator}]}
    with pytest.raises(error) as caught:
        parse(document, "robot.yaml")
    message = str(caught.value)
    assert message.startswith("robot.yaml: ") and "'j1' actuator" in message, message
    assert problem in message


@pytest.mark.slow
def test_panda_flexible_model_derivatives_and_energy():
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    from eomgen.reduction import load_for_scene

    scene = load_scene(ROOT / "examples/scenes/panda_flexible.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = apply_scene(load_for_scene(robots / "panda_description/urdf/panda.urdf", scene),
                            scene).model
    am = A.actuated_model(eomgen.derive(model))
    assert am.m == 7 and float(am.stiffness[0]) == 1e4 and float(am.damping[0]) == 0.003
    nm = numeric_model(model)
    a, w, phi = np.linspace(0.3, 0.9, 7), np.linspace(1.0, 2.5, 7), np.linspace(0, 1, 7)

    def trajectory(t):
        s, c = np.sin(w * t + phi), np.cos(w * t + phi)
        return a * s, a * w * c, -a * w ** 2 * s, -a * w ** 3 * c, a * w ** 4 * s

    t, h = 0.4, 1e-3
    tau, taud, taudd = am.link_torque_derivatives(*trajectory(t))
    L = [rnea(nm, *trajectory(t + k * h)[:3]) for k in (-2, -1, 0, 1, 2)]
    scale = np.abs(L[2]).max()
    assert np.abs(tau - L[2]).max() < 1e-12 * scale
    fd1 = (L[0] - 8 * L[1] + 8 * L[3] - L[4]) / (12 * h)
    fd2 = (-L[0] + 16 * L[1] - 30 * L[2] + 16 * L[3] - L[4]) / (12 * h * h)
    assert np.abs(taud - fd1).max() < 1e-7 * np.abs(fd1).max()
    assert np.abs(taudd - fd2).max() < 1e-5 * np.abs(fd2).max()
    # released from rest with the springs wound for gravity, no friction, no input
    free = replace(am, damping=np.zeros(7))
    x0 = A.flexible_rest_state(free, [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    x0[14:21] += 0.01  # motors off their equilibrium: the springs oscillate
    result = _integrate(free, x0, lambda t: np.zeros(7), 0.05, rtol=1e-10, atol=1e-10)
    energy = [A.flexible_energy(free, x) for x in result.y.T]
    assert np.ptp(energy) < 1e-8 * np.abs(energy).max()


def test_scene_parameters_in_actuators_stay_symbolic_or_take_their_values():
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    text = ("version: 1\nparameters: {K: 5.0e3, Bm: 0.2}\nactuators:\n"
            "  joint2: {armature: Bm, stiffness: K}\n")
    kept = apply_scene(arm, load_scene("s.yaml", text=text + "symbolic: [K]\n")).model
    stiffness = kept.movable_joints[1].actuator.stiffness
    assert stiffness == sp.Symbol("K", real=True)
    assert [p.value for p in kept.parameters if p.name == "K"] == [5.0e3]
    assert float(kept.movable_joints[1].actuator.armature) == 0.2  # Bm fixed at its value
    fixed = apply_scene(arm, load_scene("s.yaml", text=text + "symbolic: none\n")).model
    assert float(fixed.movable_joints[1].actuator.stiffness) == 5.0e3
    assert not {"K", "Bm"} & {p.name for p in fixed.parameters}
    am = A.actuated_model(eomgen.derive(kept), {"K": 123.0})
    assert am.stiffness[1] == 123.0 and np.isnan(am.stiffness[0])
    with pytest.raises(SceneError, match="stiffness -1 is negative"):
        apply_scene(arm, load_scene("s.yaml", text=text.replace("5.0e3", "-1")))
