"""Loop closures on a model with quaternion joints (NQ ≠ NV): a free-flyer trunk with a leg on
a ball hip, a leg on revolute joints and a rod on a ball joint whose tip holds the second leg's
shin (a point loop), against Pinocchio built here by hand from the same list of joints
(``JointModelFreeFlyer``, ``JointModelSpherical``, ``JointModelRevoluteUnaligned``; q and v
passed unchanged, no adapter):

* the loop's frame on the rod is placed from Pinocchio's kinematics at a configuration ``q*``,
  so ``Φ(q*) = 0``; elsewhere ``Φ``, ``J_l`` and ``J̇_l v`` are Pinocchio's frame placements,
  ``LOCAL_WORLD_ALIGNED`` frame Jacobians and classical accelerations at ``a = 0``, frame b
  less frame a;
* the constrained accelerations and loop forces are ``constraintDynamics``' with a
  ``CONTACT_3D`` ``RigidConstraintModel`` between the two joints in ``LOCAL_WORLD_ALIGNED``,
  whose ``lambda_c`` is the force on frame a's side: ``λ = −λ_pin``;
* a simulation's trajectory is an RK4 of ``constraintDynamics`` written here (the configuration
  embedded, its quaternions' rates ``½ q ⊗ (ω, 0)``), compared with ``pin.difference``.
* the constrained dynamics' derivatives (along the tangent) are
  ``computeConstraintDynamicsDerivatives``'.

The generated NumPy module is checked (every backend in the slow test), and the numeric
:class:`eomgen.numeric.loops.LoopDynamics` (Newton closure on the manifold, the parallel inverse
dynamics) and :func:`eomgen.numeric.loops.pinocchio_loops` through eomgen's adapter.
"""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.model.floating import add_free_flyer
from eomgen.numeric.loops import LoopDynamics
from eomgen.model import Joint, JointType, Link, Transform, build_model, vec3
from eomgen.model.configuration import integrate
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import relative
from support.extras import need
from support.generated import generated
from support.reference import random_inertial

pin = need("pinocchio", reason="Pinocchio is the reference")

#: (joint, kind, parent link, origin [m], axis); names sort in depth-first order.
SPEC = (("a_hip", "spherical", "trunk", (0.25, 0.12, 0.0), (0, 1, 0)),
        ("b_knee", "revolute", "a_hip_link", (0.0, 0.0, -0.25), (0, 1, 0)),
        ("c_hip", "revolute", "trunk", (-0.25, 0.12, 0.0), (0, 1, 0)),
        ("d_knee", "revolute", "c_hip_link", (0.0, 0.0, -0.25), (0.3, 0.9, 0.1)),
        ("e_rod", "spherical", "trunk", (-0.05, 0.12, -0.02), (0, 0, 1)))
GRAVITY = np.array([0.2, -0.1, -9.81])
SHIN_TIP = np.array([0.0, 0.0, -0.25])  # frame b, in d_knee_link
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
FUNCTIONS = ["loop_constraint", "loop_jacobian", "loop_bias", "constrained_forward_dynamics",
             "parallel_inverse_dynamics"]


def _inertia(inertial):
    return pin.Inertia(float(inertial.mass), np.array([float(x) for x in inertial.com]),
                       np.array([[float(x) for x in row] for row in inertial.inertia]))


def _configuration(pm, rng):
    """A random configuration of Pinocchio's model: unit quaternions, the rest in [−1, 1]."""
    q = rng.uniform(-1, 1, pm.nq)
    for joint in pm.joints[1:]:
        if joint.nq > 1:
            x = rng.normal(size=4)
            q[joint.idx_q + joint.nq - 4:joint.idx_q + joint.nq] = x / np.linalg.norm(x)
    return q


def _robots():
    """eomgen's model (no loop yet), Pinocchio's by hand, its joint ids by link, and ``q*``."""
    rng = np.random.default_rng(7)
    trunk = random_inertial(rng)
    links, joints = [Link("trunk", trunk)], []
    pm = pin.Model()
    pm.gravity = pin.Motion(GRAVITY, np.zeros(3))
    ids = {"trunk": pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")}
    pm.appendBodyToJoint(ids["trunk"], _inertia(trunk), pin.SE3.Identity())
    for name, kind, parent, xyz, axis in SPEC:
        inertial = random_inertial(rng)
        axis = np.array(axis, float) / np.linalg.norm(axis)
        links.append(Link(f"{name}_link", inertial))
        joints.append(Joint(name, JointType.SPHERICAL if kind == "spherical" else
                            JointType.REVOLUTE, parent, f"{name}_link",
                            Transform(translation=vec3(list(xyz))), vec3(axis.tolist())))
        jm = pin.JointModelSpherical() if kind == "spherical" else \
            pin.JointModelRevoluteUnaligned(axis)
        ids[f"{name}_link"] = pm.addJoint(ids[parent], jm, pin.SE3(np.eye(3), np.array(xyz)),
                                          name)
        pm.appendBodyToJoint(ids[f"{name}_link"], _inertia(inertial), pin.SE3.Identity())
    model = add_free_flyer(build_model("<test>", "quadruped", links, joints,
                                       gravity=GRAVITY.tolist()))
    q_star = _configuration(pm, rng)
    return model, pm, ids, q_star


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """The closed model (through a scene: its loop; the ball hip, the first knee and the second hip
    actuated, the ball hip by name), its
    LoopDynamics, the generated NumPy module, Pinocchio's model with the loop's two frames and
    constraint, and ``q*``."""
    model, pm, ids, q_star = _robots()
    data = pm.createData()
    pin.forwardKinematics(pm, data, q_star)
    rod = data.oMi[ids["e_rod_link"]].inverse() * data.oMi[ids["d_knee_link"]] \
        * pin.SE3(np.eye(3), SHIN_TIP)  # frame a: the shin's tip at q*, on the rod
    text = ("version: 1\nloops:\n  - {name: rod, type: point, "
            f"a: {{link: e_rod_link, xyz: [{', '.join(map(repr, rod.translation.tolist()))}]}}, "
            f"b: {{link: d_knee_link, xyz: [{', '.join(map(repr, SHIN_TIP.tolist()))}]}}}}\n"
            "actuated: [a_hip, b_knee, c_hip]\n")
    closed = apply_scene(model, load_scene("quadruped_loop.yaml", text=text)).model
    frames = [pm.addFrame(pin.Frame(name, ids[link], 0, placement, pin.FrameType.OP_FRAME))
              for name, link, placement in
              (("a", "e_rod_link", pin.SE3(np.eye(3), rod.translation)),
               ("b", "d_knee_link", pin.SE3(np.eye(3), SHIN_TIP)))]
    constraint = pin.RigidConstraintModel(
        pin.ContactType.CONTACT_3D, pm, ids["e_rod_link"], pm.frames[frames[0]].placement,
        ids["d_knee_link"], pm.frames[frames[1]].placement, LWA)
    _, modules = generated(closed, FUNCTIONS, tmp_path_factory.mktemp("quadruped"), ("numpy",))
    return {"model": closed, "dyn": LoopDynamics(closed), "module": modules["numpy"],
            "pm": pm, "frames": frames, "constraint": constraint, "q_star": q_star}


def _closed_states(case, count, seed):
    """Closed configurations near q* (the actuated joints moved, the base, the second knee
    and the rod by Newton),
    velocities in the null space of J_l, random efforts."""
    dyn, rng = case["dyn"], np.random.default_rng(seed)
    out = []
    for _ in range(count):
        step = np.zeros(dyn.model.dof)
        step[dyn.actuated] = rng.uniform(-0.1, 0.1, len(dyn.actuated))
        q = dyn.assemble(integrate(case["q_star"], step, 1.0, dyn.model))
        N = np.linalg.svd(dyn.loop_jacobian(q))[2][3:].T
        out.append((q, N @ rng.uniform(-1, 1, N.shape[1]), rng.uniform(-1, 1, dyn.model.dof)))
    return out


def _pinocchio_dynamics(case, settings=None):
    pm = case["pm"]
    data = pm.createData()
    models = pin.StdVec_RigidConstraintModel()
    models.append(case["constraint"])
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm, data, models, datas)
    settings = settings or pin.ProximalSettings(1e-14, 0.0, 100)

    def accelerations(q, v, tau):
        a = pin.constraintDynamics(pm, data, q, v, tau, models, datas, settings)
        return a.copy(), -data.lambda_c.copy()  # the force on frame b, world axes
    return accelerations


def test_scene_names_the_loop_rows_and_the_ball_joint_as_actuated(case):
    model, module = case["model"], case["module"]
    assert (model.nq, model.dof) == (case["pm"].nq, case["pm"].nv) == (18, 15)
    assert tuple(module["LOOP_ROWS"]) == ("rod.x", "rod.y", "rod.z")
    assert tuple(module["ACTUATED_JOINTS"]) == ("a_hip_wx", "a_hip_wy", "a_hip_wz", "b_knee",
                                                "c_hip")


def test_loop_rows_against_pinocchio_frames(case):
    """Φ vanishes at q* and equals Pinocchio's frame placements elsewhere; J_l and J̇_l v are
    its world-aligned frame Jacobians and classical accelerations at a = 0 (b less a)."""
    module, dyn, pm = case["module"], case["dyn"], case["pm"]
    fa, fb = case["frames"]
    assert np.abs(module["loop_constraint"](case["q_star"])).max() < 1e-14
    data = pm.createData()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = _configuration(pm, rng)
        q[3:7] *= 1.7  # a quaternion that is not unit: the normalised one is used
        v = rng.uniform(-2, 2, pm.nv)
        qn = pin.normalize(pm, q)
        pin.forwardKinematics(pm, data, qn, v, np.zeros(pm.nv))
        pin.computeJointJacobians(pm, data, qn)
        pin.updateFramePlacements(pm, data)
        phi = data.oMf[fb].translation - data.oMf[fa].translation
        J = (pin.getFrameJacobian(pm, data, fb, LWA) - pin.getFrameJacobian(pm, data, fa, LWA))[:3]
        bias = (pin.getFrameClassicalAcceleration(pm, data, fb, LWA).linear
                - pin.getFrameClassicalAcceleration(pm, data, fa, LWA).linear)
        assert relative(module["loop_constraint"](q), phi) < 1e-10
        assert relative(module["loop_jacobian"](q), J) < 1e-10
        assert relative(module["loop_bias"](q, v), bias) < 1e-10
        e = dyn.evaluate(q, v)
        assert relative(e["Phi_l"], phi) < 1e-10 and relative(e["dJqd_l"], bias) < 1e-10
        assert relative(e["J_l"], J) < 1e-10


def test_constrained_dynamics_against_pinocchio(case):
    """q̈ and the loop force of the generated module and of LoopDynamics are constraintDynamics'
    at closed states; the parallel inverse dynamics (the base, the second knee and the rod
    passive) gives back the efforts and the force of a motion driven by the actuated joints
    alone."""
    module, dyn = case["module"], case["dyn"]
    reference = _pinocchio_dynamics(case)
    for q, v, tau in _closed_states(case, 2, seed=11):
        assert np.abs(dyn.loop_constraint(q)).max() <= 1e-12
        for k in range(len(dyn.model.quaternion_joints)):  # Newton kept them unit
            joint = dyn.model.quaternion_joints[k]
            assert abs(np.linalg.norm(q[joint.quaternion:joint.quaternion + 4]) - 1) < 1e-14
        a_pin, lam_pin = reference(q, v, tau)
        qdd, lam = (np.asarray(x) for x in module["constrained_forward_dynamics"](q, v, tau))
        assert relative(qdd, a_pin) < 1e-10 and relative(lam, lam_pin) < 1e-10
        qdd_n, lam_n = dyn.constrained_forward_dynamics(q, v, tau)
        assert relative(qdd_n, a_pin) < 1e-10 and relative(lam_n, lam_pin) < 1e-10
        tau[dyn.passive] = 0.0
        a_pin, lam_pin = reference(q, v, tau)
        tau_a, lam_id = dyn.parallel_inverse_dynamics(q, v, a_pin)
        assert relative(tau_a, tau[dyn.actuated]) < 1e-10 and relative(lam_id, lam_pin) < 1e-10
        tau_g, lam_g = module["parallel_inverse_dynamics"](q, v, a_pin)
        assert relative(tau_g, tau) < 1e-10 and relative(lam_g, lam_pin) < 1e-10


def test_pinocchio_loops_through_the_adapter(case):
    """eomgen's adapter (one Pinocchio joint per ball joint and free flyer) and
    pinocchio_loops give the same q̈ and force as the model built by hand."""
    from eomgen.numeric.loops import pinocchio_loops
    from eomgen.numeric.pinocchio import to_pinocchio

    pm = to_pinocchio(case["model"])
    models = pinocchio_loops(case["model"], pm, LWA)
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm.model, pm.data, models, datas)
    reference = _pinocchio_dynamics(case)
    (q, v, tau), = _closed_states(case, 1, seed=5)
    a = pin.constraintDynamics(pm.model, pm.data, q[pm.qperm], v[pm.perm], tau[pm.perm], models,
                               datas, pin.ProximalSettings(1e-14, 0.0, 100))
    qdd = np.empty_like(a)
    qdd[pm.perm] = a
    a_ref, lam_ref = reference(q, v, tau)
    assert relative(qdd, a_ref) < 1e-10 and relative(-pm.data.lambda_c, lam_ref) < 1e-10


def _quaternion_rate(x, w):
    """``½ x ⊗ (ω, 0)`` of a quaternion ``x`` (x, y, z, w) and a body angular velocity."""
    v, s = x[:3], x[3]
    return 0.5 * np.concatenate([s * w + np.cross(v, w), [-v @ w]])


def test_simulation_against_an_rk4_of_pinocchio(case):
    """eomgen's RK4 (on the manifold) holding the loop, from a closed state, against an RK4 of
    constraintDynamics written here on the embedded configuration: the same trajectory over
    0.1 s (pin.difference), quaternions unit, the loop closed, the energy kept."""
    from eomgen.analysis.simulate import RK4, simulate
    from eomgen.analysis.simulate_loops import LoopSystem, run_loop_study

    model, pm = case["model"], case["pm"]
    (q0, v0, _), = _closed_states(case, 1, seed=2)
    system = LoopSystem(model, dynamics=case["dyn"])
    trajectory, _ = simulate(system, RK4(dt=1e-3), q0, v0, 0.1, points=11)
    reference = _pinocchio_dynamics(case)

    def rates(q, v):
        """(q̇, q̈): each Pinocchio joint's configuration rate, and constraintDynamics."""
        qdot = np.empty(pm.nq)
        for joint in pm.joints[1:]:
            iq, iv = joint.idx_q, joint.idx_v
            if joint.nq == 7:  # the free flyer: the origin moves at R v_lin
                R = pin.XYZQUATToSE3(np.r_[0.0, 0.0, 0.0, q[iq + 3:iq + 7]]).rotation
                qdot[iq:iq + 3] = R @ v[iv:iv + 3]
                iq, iv = iq + 3, iv + 3
            if joint.nq >= 4:
                qdot[iq:iq + 4] = _quaternion_rate(q[iq:iq + 4], v[iv:iv + 3])
            else:
                qdot[iq] = v[iv]
        return qdot, reference(pin.normalize(pm, q), v, np.zeros(pm.nv))[0]

    q, v, h = q0.copy(), v0.copy(), 1e-3
    for _ in range(100):
        k1 = rates(q, v)
        k2 = rates(q + h / 2 * k1[0], v + h / 2 * k1[1])
        k3 = rates(q + h / 2 * k2[0], v + h / 2 * k2[1])
        k4 = rates(q + h * k3[0], v + h * k3[1])
        q = q + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    q_end, v_end = trajectory.q[-1], trajectory.qd[-1]
    assert np.abs(pin.difference(pm, pin.normalize(pm, q), q_end)).max() < 1e-9
    assert np.abs(v_end - v).max() < 1e-8 * max(1.0, np.abs(v).max())
    for joint in model.quaternion_joints:
        assert abs(np.linalg.norm(q_end[joint.quaternion:joint.quaternion + 4]) - 1) < 1e-13
    assert np.abs(case["dyn"].loop_constraint(q_end)).max() < 1e-9
    study = run_loop_study(model, [RK4(dt=2e-3)], 0.02, q0, v0, points=3)
    assert [r.status for r in study.runs] == ["ok", "ok"]
    assert max(r.drift for r in study.runs) < 1e-9
    assert max(r.relative_energy_drift for r in study.runs) < 1e-7


@pytest.mark.slow  # every backend generated and loaded (the fast one compiled)
def test_every_backend_prints_the_quaternion_loop_rows(case, tmp_path):
    calls, modules = generated(case["model"], FUNCTIONS, tmp_path)
    module = case["module"]
    (q, v, tau), = _closed_states(case, 1, seed=9)
    q = integrate(q, np.full(case["model"].dof, 0.01), 1.0, case["model"])  # slightly open
    expected = {"loop_constraint": (q,), "loop_jacobian": (q,), "loop_bias": (q, v)}
    qdd_ref, F_ref = module["constrained_forward_dynamics"](q, v, tau)
    for backend, call in calls.items():
        for function, args in expected.items():
            value = np.asarray(module[function](*args))
            got = call(function, *args).reshape(value.shape)
            assert relative(got, value) < 1e-12, (backend, function)
        f = modules[backend]["constrained_forward_dynamics"]
        if backend == "casadi":
            out = f.call({"q": q, "qd": v, "tau": tau})
            qdd, F = np.array(out["qdd"]).ravel(), np.array(out["F_c"]).ravel()
        else:
            qdd, F = (np.asarray(x, dtype=float) for x in f(q, v, tau))
        assert relative(qdd, qdd_ref) < 1e-10 and relative(F, F_ref) < 1e-10, backend


@pytest.mark.slow  # the derivatives' program is generated: about 10 s
def test_constrained_derivatives_against_pinocchio(case, tmp_path):
    """The generated constrained_forward_dynamics_derivatives (dKKT along the tangent) with the
    loop's rows: Pinocchio's computeConstraintDynamicsDerivatives of the same constraint
    (ddq_dq, ddq_dv, ddq_dtau; dlambda_* of the force on frame a, so negated)."""
    _, modules = generated(case["model"], ["constrained_forward_dynamics_derivatives"], tmp_path,
                           ("numpy",))
    pm = case["pm"]
    data = pm.createData()
    models = pin.StdVec_RigidConstraintModel()
    models.append(case["constraint"])
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm, data, models, datas)
    (q, v, tau), = _closed_states(case, 1, seed=4)
    ours = modules["numpy"]["constrained_forward_dynamics_derivatives"](q, v, tau)
    pin.constraintDynamics(pm, data, q, v, tau, models, datas,
                           pin.ProximalSettings(1e-14, 0.0, 100))
    pin.computeConstraintDynamicsDerivatives(pm, data, models, datas)
    expected = (data.ddq_dq, data.ddq_dv, data.ddq_dtau,
                -data.dlambda_dq, -data.dlambda_dv, -data.dlambda_dtau)
    for name, got, value in zip(("dqdd_dq", "dqdd_dqd", "dqdd_dtau", "dF_dq", "dF_dqd",
                                 "dF_dtau"), ours, expected):
        assert relative(got, value) < 1e-10, name
