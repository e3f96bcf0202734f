"""Derivatives of the dynamics on models with coupled joints (issue 25 on the couplings of issue
26): ``inverse_dynamics_derivatives``, ``forward_dynamics_derivatives``, ``gravity_derivative``,
``linearize`` and the drive derivatives in the independent coordinates.

Model: a fixed-base five-joint spatial arm (MJCF, a drive on every joint; axes along the link
frames but l2 turned by a general rotation, which keeps the program small) with a scene coupling
``j3 = -0.7 j2 + 0.3`` and a differential ``j5 = 0.05 j1 - 0.02 j4 + 0.01`` (a slide), and a
payload whose mass ``m_load`` stays symbolic: independent ``q = (j1, j2, j4)``,
``q_full = T q + c``. Along the tangent (∂/∂q of quaternion joints): a ball joint after a
follower, and (slow) the free-flying MJCF model of tests/data/mjcf/coupled_floating.xml (a
free joint, a ball joint, a coupling below them); (slow) the Panda with its mimic finger.

References: Pinocchio 4.1 on the whole tree (its derivative algorithms refuse mimic joints):
``computeRNEADerivatives`` and ``computeGeneralizedGravityDerivatives`` at
``(T q + c, T q̇, T q̈)`` projected, ``Tᵀ ∂τ/∂x T``; the forward dynamics'
``−M_r⁻¹ Tᵀ ∂τ/∂x T`` at the reduced ``q̈_r = M_r⁻¹ (τ_r − Tᵀ h)`` (M_r = Tᵀ crba T, with the
drives ``Tᵀ (M + diag(a)) T`` and the smoothed friction's slope); central differences of the
generated τ, g, forward dynamics (default and overridden ``m_load``); the CasADi module
against the NumPy module, (slow) every backend.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model import joint_actuators, uncoupled
from eomgen.model.coupling import coupling_map, full_configuration
from eomgen.outputs import OUTPUTS
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import TESTS, erd_robots_or_skip
from support.derivatives import results
from support.generated import BACKENDS, generated
from support.extras import need

pin = need("pinocchio", reason="checked against Pinocchio's derivatives")

GRAVITY = np.array([0.3, -0.2, -9.81])
DRIVE = 'armature="{a}" damping="{d}" frictionloss="{f}"'
ARM = f"""<mujoco model="geared"><option gravity="0.3 -0.2 -9.81"/><worldbody>
<body name="l1" pos="0 0 0.1"><joint name="j1" axis="0 0 1" {DRIVE.format(a=0.05, d=0.3, f=0.2)}/>
<inertial pos="0.01 0.02 0.1" mass="2" fullinertia="0.02 0.03 0.025 0.001 0.002 -0.001"/>
<body name="l2" pos="0 0.05 0.2" quat="0.9 0.1 0.3 0.2"><joint name="j2" axis="0 1 0" {DRIVE.format(a=0.08, d=0.2, f=0.1)}/>
<inertial pos="0.2 0.01 -0.02" mass="1.5" fullinertia="0.015 0.025 0.02 0.001 0 0.002"/>
<body name="l3" pos="0.4 0 0"><joint name="j3" axis="0 0 1" {DRIVE.format(a=0.03, d=0.15, f=0.05)}/>
<inertial pos="0.1 -0.02 0.01" mass="1" diaginertia="0.008 0.012 0.01"/>
<body name="l4" pos="0.3 0 0.05"><joint name="j4" axis="1 0 0" {DRIVE.format(a=0.02, d=0.1, f=0.08)}/>
<inertial pos="0.02 0.05 0" mass="0.5" diaginertia="0.003 0.002 0.004"/>
<body name="l5" pos="0.1 0.02 0"><joint name="j5" type="slide" axis="0 0 1" {DRIVE.format(a=0.4, d=2, f=0.3)}/>
<inertial pos="0 0.01 0.03" mass="0.3" diaginertia="0.001 0.002 0.0015"/>
</body></body></body></body></body></worldbody></mujoco>"""
SCENE = """version: 1
parameters: {m_load: 0.4}
symbolic: [m_load]
payloads: [{link: l5, mass: m_load, com: [0.05, 0, 0.02]}]
couplings:
  - {joint: j3, to: j2, ratio: -0.7, offset: 0.3}
  - {joint: j5, to: {j1: 0.05, j4: -0.02}, offset: 0.01}
"""
#: a hinge, a hinge following it, a ball joint, a hinge (Pinocchio's q: ja, jb, quaternion,
#: jd), a drive on every hinge
BALL_AFTER = f"""<mujoco model="ball_after"><option gravity="0.3 -0.2 -9.81"/><worldbody>
<body name="a" pos="0 0 0.1"><joint name="ja" axis="0 0 1" {DRIVE.format(a=0.05, d=0.3, f=0.2)}/>
<inertial pos="0.01 0.02 0.1" mass="2" fullinertia="0.02 0.03 0.025 0.001 0.002 -0.001"/>
<body name="b" pos="0 0.05 0.2" quat="0.9 0.1 0.3 0.2"><joint name="jb" axis="0 1 0" {DRIVE.format(a=0.08, d=0.2, f=0.1)}/>
<inertial pos="0.2 0.01 -0.02" mass="1.5" fullinertia="0.015 0.025 0.02 0.001 0 0.002"/>
<body name="c" pos="0.3 0 0.05"><joint name="ball" type="ball"/>
<inertial pos="0.02 0.05 0.1" mass="0.5" fullinertia="0.003 0.002 0.004 0.0002 0 0.0001"/>
<body name="d" pos="0.1 0.02 0.2"><joint name="jd" axis="1 0 0" {DRIVE.format(a=0.02, d=0.1, f=0.08)}/>
<inertial pos="0 0.01 0.03" mass="0.3" diaginertia="0.001 0.002 0.0015"/>
</body></body></body></body></worldbody>
<equality><joint name="gear" joint1="jb" joint2="ja" polycoef="0.1 -0.6 0 0 0"/></equality>
</mujoco>"""
LOAD, LOAD_COM = 0.4, np.array([0.05, 0, 0.02])
DERIVATIVES = ["inverse_dynamics_derivatives", "forward_dynamics_derivatives",
               "gravity_derivative", "linearize", "drive_inverse_dynamics_derivatives",
               "drive_forward_dynamics_derivatives"]
FUNCTIONS = DERIVATIVES + ["inverse_dynamics", "forward_dynamics", "gravity_vector",
                           "drive_mass_matrix", "friction_torque_smooth"]


def coupled_arm(folder):
    need("mujoco", reason="the model is MJCF, read by MuJoCo's compiler")
    path = folder / "geared.xml"
    path.write_text(ARM, encoding="utf-8")
    scene = load_scene(folder / "scene.yaml", text=SCENE)
    return path, apply_scene(eomgen.load(path), scene).model


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    """(model, {backend: call} of NumPy and CasADi, the NumPy module, Pinocchio's whole tree
    with the payload, T, c, drives (a, d, f, w) of the whole tree)."""
    folder = tmp_path_factory.mktemp("coupled")
    path, model = coupled_arm(folder)
    assert model.joint_names == ("j1", "j2", "j4")
    calls, modules = generated(model, FUNCTIONS, folder, backends=("numpy", "casadi"))
    calls["casadi_module"] = modules.get("casadi")
    pm = pin.buildModelFromMJCF(str(path))
    pm.gravity = pin.Motion(GRAVITY, np.zeros(3))
    pm.armature = np.zeros(pm.nv)   # Pinocchio reads MJCF's armature into crba: added below
    assert [pm.names[k] for k in range(1, pm.njoints)] == ["j1", "j2", "j3", "j4", "j5"]
    add_load(pm, LOAD)
    T, c = (np.array(x, dtype=float) for x in coupling_map(model))
    drives = joint_actuators(uncoupled(model))
    a, d, f, w = (np.array([float(getattr(x, k)) for x in drives])
                  for k in ("armature", "damping", "friction", "friction_width"))
    assert np.all(a > 0) and np.all(f > 0)
    return model, calls, modules["numpy"], pm, T, c.ravel(), (a, d, f, w)


def add_load(pm, mass):
    """The scene's point payload on l5 (Pinocchio joint 5)."""
    pm.appendBodyToJoint(5, pin.Inertia(mass, LOAD_COM, np.zeros((3, 3))), pin.SE3.Identity())


def relative(ours, theirs):
    return np.abs(ours - theirs).max() / max(1.0, np.abs(theirs).max())


def states(n, count, seed):
    rng = np.random.default_rng(seed)
    return [tuple(rng.uniform(-1.2, 1.2, n) for _ in range(3)) for _ in range(count)]


def reference(pm, T, qf, v, u, drives=None):
    """Pinocchio's whole tree at the full configuration ``qf``, ``T v``, projected:
    (∂τ_r/∂q, ∂τ_r/∂q̇), ∂g_r/∂q at q̈_r = u and the forward dynamics' (∂q̈/∂q, ∂q̈/∂q̇,
    M_r⁻¹) at τ_r = u; with ``drives`` (a, d, f, w) the drives' ∂τ_a/∂q̇ and their forward
    dynamics'."""
    data = pm.createData()
    vf = T @ v
    M = pin.crba(pm, data, qf)
    M = np.triu(M) + np.triu(M, 1).T
    h = pin.nonLinearEffects(pm, data, qf, vf)
    extra, slope, friction = np.zeros_like(M), np.zeros(len(vf)), np.zeros(len(vf))
    if drives is not None:
        a, d, f, w = drives
        extra, friction = np.diag(a), d * vf + f * np.tanh(vf / w)
        slope = d + f / w * (1 - np.tanh(vf / w) ** 2)
    pin.computeRNEADerivatives(pm, data, qf, vf, T @ u)
    dtau = (T.T @ data.dtau_dq @ T, T.T @ data.dtau_dv @ T)
    dg = T.T @ pin.computeGeneralizedGravityDerivatives(pm, data, qf) @ T
    M_r = T.T @ (M + extra) @ T
    Minv = np.linalg.inv(M_r)
    qdd = np.linalg.solve(M_r, u - T.T @ (h + friction))
    pin.computeRNEADerivatives(pm, data, qf, vf, T @ qdd)
    dq, dv = T.T @ data.dtau_dq @ T, T.T @ (data.dtau_dv + np.diag(slope)) @ T
    return dtau, dg, (-Minv @ dq, -Minv @ dv, Minv)


def test_derivatives_equal_pinocchios_projected(arm):
    model, _, call, pm, T, c, drives = arm
    n = model.dof
    for q, v, u in states(n, 3, seed=5):
        dtau, dg, forward = reference(pm, T, T @ q + c, v, u)
        got = call["inverse_dynamics_derivatives"](q, v, u)
        for name, ours, theirs in zip(("dtau_dq", "dtau_dqd"), got, dtau):
            assert ours.shape == (n, n)
            assert relative(ours, theirs) <= 1e-10, name
        assert relative(call["gravity_derivative"](q), dg) <= 1e-10
        got = call["forward_dynamics_derivatives"](q, v, u)
        for name, ours, theirs in zip(("dqdd_dq", "dqdd_dqd", "Minv"), got, forward):
            assert relative(ours, theirs) <= 1e-10, name
        A, B = call["linearize"](q, v, u)
        assert A.shape == (2 * n, 2 * n) and B.shape == (2 * n, n)
        np.testing.assert_array_equal(A[:n], np.hstack([np.zeros((n, n)), np.eye(n)]))
        assert relative(A[n:], np.hstack(forward[:2])) <= 1e-10
        assert relative(B, np.vstack([np.zeros((n, n)), forward[2]])) <= 1e-10


def test_drive_derivatives_equal_pinocchios_projected(arm):
    model, _, call, pm, T, c, drives = arm
    a, d, f, w = drives
    for q, v, u in states(model.dof, 2, seed=6):
        (dq, dv), _, forward = reference(pm, T, T @ q + c, v, u, drives)
        got = call["drive_inverse_dynamics_derivatives"](q, v, u)
        assert relative(got[0], dq) <= 1e-10
        assert relative(got[1], dv + T.T @ np.diag(d) @ T) <= 1e-10
        got = call["drive_forward_dynamics_derivatives"](q, v, u)
        for name, ours, theirs in zip(("dqdd_a_dq", "dqdd_a_dqd", "Minv_a"), got, forward):
            assert relative(ours, theirs) <= 1e-10, name


def central_difference(f, x, h=1e-6):
    columns = []
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        columns.append((np.asarray(f(x + e)).ravel() - np.asarray(f(x - e)).ravel()) / (2 * h))
    return np.stack(columns, axis=-1)


@pytest.mark.parametrize("m_load", [None, 1.3])
def test_derivatives_are_central_differences_of_the_generated_dynamics(arm, m_load):
    """At the payload's default mass and at ``m_load=1.3`` (a keyword argument)."""
    model, calls, module, *_ = arm
    call = calls["numpy"]
    kw = {} if m_load is None else {"m_load": m_load}
    q, v, u = states(model.dof, 1, seed=8)[0]

    def drive_forward(q, v, u):
        effort = u - call("friction_torque_smooth", v, **kw).ravel()
        bias = call("inverse_dynamics", q, v, np.zeros_like(q), **kw).ravel()
        return np.linalg.solve(call("drive_mass_matrix", q, **kw), effort - bias)

    fd = lambda q, v, u: call("forward_dynamics", q, v, u, **kw)  # noqa: E731
    tau = lambda q, v, u: call("inverse_dynamics", q, v, u, **kw)  # noqa: E731
    dq, dv = module["inverse_dynamics_derivatives"](q, v, u, **kw)
    assert relative(dq, central_difference(lambda x: tau(x, v, u), q)) <= 1e-6
    assert relative(dv, central_difference(lambda x: tau(q, x, u), v)) <= 1e-6
    assert relative(call("gravity_derivative", q, **kw),
                    central_difference(lambda x: call("gravity_vector", x, **kw), q)) <= 1e-6
    for function, forward in (("forward_dynamics_derivatives", fd),
                              ("drive_forward_dynamics_derivatives", drive_forward)):
        dq, dv, Minv = module[function](q, v, u, **kw)
        assert relative(dq, central_difference(lambda x: forward(x, v, u), q)) <= 1e-6
        assert relative(dv, central_difference(lambda x: forward(q, x, u), v)) <= 1e-6
        assert relative(Minv, central_difference(lambda x: forward(q, v, x), u)) <= 1e-6
    if m_load is not None:  # the keyword argument reaches the derivatives
        assert relative(dq, module["drive_forward_dynamics_derivatives"](q, v, u)[0]) > 1e-3


def arguments(function, q, v, u) -> tuple:
    return tuple({"q": q, "qd": v, "qdd": u, "tau": u}[x] for x in OUTPUTS[function].inputs)


def test_casadi_gives_the_numpy_modules_derivatives(arm):
    model, calls, module, *_ = arm
    if calls["casadi_module"] is None:
        pytest.skip("CasADi is not installed")
    for q, v, u in states(model.dof, 2, seed=9):
        for function in DERIVATIVES:
            args = arguments(function, q, v, u)
            for kw in ({}, {"m_load": 1.3}):
                theirs = results("numpy", module, function, *args, **kw)
                ours = results("casadi", calls["casadi_module"], function, *args, **kw)
                for part, expected in zip(ours, theirs):
                    assert relative(part, expected) <= 1e-12, function


@pytest.mark.slow
def test_every_backend_gives_the_numpy_modules_derivatives(tmp_path):
    """NumPy, CasADi, the fast module, JAX and PyTorch print the same coupled programs.
    (CasADi's C library and the plain C kernels print CasADi's functions and the same
    straight-line program: their printers are checked on the uncoupled derivatives,
    tests/derivatives/test_c_kernels.py.)"""
    _, model = coupled_arm(tmp_path)
    _, modules = generated(model, DERIVATIVES, tmp_path)
    assert set(modules) == set(BACKENDS)
    for q, v, u in states(model.dof, 1, seed=10):
        for function in DERIVATIVES:
            args = arguments(function, q, v, u)
            theirs = results("numpy", modules["numpy"], function, *args, m_load=0.9)
            for backend, module in modules.items():
                ours = results(backend, module, function, *args, m_load=0.9)
                assert len(ours) == len(theirs)
                for part, expected in zip(ours, theirs):
                    assert relative(part, expected) <= 1e-12, (backend, function)


def skew(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def assert_tangent_derivatives(path, independent, seed):
    """The derivatives of the MJCF model at ``path`` (quaternion joints and a coupling) equal
    Pinocchio's on the whole tree read from the same file, projected, ∂/∂q along the tangent
    of the independent configuration (``independent``: its entries' indices in Pinocchio's q),
    the drive derivatives too;
    ``linearize``'s position rows those of the tangent chart (docs/derivatives.md), 0 on the
    one-axis joints."""
    need("mujoco", reason="the model is MJCF, read by MuJoCo's compiler")
    model = eomgen.load(path)
    module = eomgen.derive(model, ("dtau", "dqdd", "dg_dq", "AB", "dtau_a", "dqdd_a")
                           ).lambdify().module
    drives = joint_actuators(uncoupled(model))   # per velocity of the tree (0 on quaternions)
    drives = tuple(np.array([float(getattr(x, k)) for x in drives])
                   for k in ("armature", "damping", "friction", "friction_width"))
    pm = pin.buildModelFromMJCF(str(path))
    pm.gravity = pin.Motion(GRAVITY, np.zeros(3))
    pm.armature = np.zeros(pm.nv)
    T = np.array(coupling_map(model)[0], dtype=float)
    n, rng = model.dof, np.random.default_rng(seed)
    for _ in range(2):
        full = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        q = full[independent]
        qf = np.array(full_configuration(model, q), dtype=float)
        v, u = rng.normal(size=(2, n))
        dtau, dg, forward = reference(pm, T, qf, v, u)
        for ours, theirs in zip(module.inverse_dynamics_derivatives(q, v, u), dtau):
            assert relative(ours, theirs) <= 1e-10
        assert relative(module.gravity_derivative(q), dg) <= 1e-10
        for name, ours, theirs in zip(("dq", "dv", "Minv"),
                                      module.forward_dynamics_derivatives(q, v, u), forward):
            assert relative(ours, theirs) <= 1e-9, name
        (dq, dv), _, forward = reference(pm, T, qf, v, u, drives)
        ours = module.drive_inverse_dynamics_derivatives(q, v, u)
        assert relative(ours[0], dq) <= 1e-10
        assert relative(ours[1], dv + T.T @ np.diag(drives[1]) @ T) <= 1e-10
        for ours, theirs in zip(module.drive_forward_dynamics_derivatives(q, v, u), forward):
            assert relative(ours, theirs) <= 1e-9
        A, _ = module.linearize(q, v, u)
        transport = np.zeros((n, n))   # −½ ad_v of SE(3), −½ [ω]× of SO(3)
        for joint in model.quaternion_joints:
            k = joint.v_index + joint.nv - 3
            transport[k:k + 3, k:k + 3] = -0.5 * skew(v[k:k + 3])
            if joint.nv == 6:
                transport[k - 3:k, k - 3:k] = -0.5 * skew(v[k:k + 3])
                transport[k - 3:k, k:k + 3] = -0.5 * skew(v[k - 3:k])
        assert relative(A[:n, :n], transport) <= 1e-12
        np.testing.assert_array_equal(A[:n, n:], np.eye(n))


def test_a_ball_joint_after_a_follower_along_the_tangent(tmp_path):
    """``jb = −0.6 ja + 0.1`` before a ball joint: the ball's velocity and configuration
    entries sit one place earlier in the independent coordinates than in the whole tree."""
    need("mujoco", reason="the model is MJCF, read by MuJoCo's compiler")
    path = tmp_path / "ball_after.xml"
    path.write_text(BALL_AFTER, encoding="utf-8")
    assert_tangent_derivatives(path, [0, 2, 3, 4, 5, 6], seed=13)


@pytest.mark.slow
def test_floating_coupled_derivatives_equal_pinocchios_along_the_tangent():
    """A free joint, a ball joint and ankle = −0.6 knee + 0.1 below them."""
    assert_tangent_derivatives(TESTS / "data" / "mjcf" / "coupled_floating.xml",
                               list(range(12)) + [13], seed=11)   # all but the ankle


@pytest.mark.slow
def test_panda_with_a_mimic_finger_equals_pinocchios_projected():
    """The Panda, ``panda_finger_joint2`` following ``panda_finger_joint1`` (URDF <mimic>, 8
    coordinates): every derivative against Pinocchio's whole tree (9 joints), projected."""
    import warnings

    path = erd_robots_or_skip() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(path)
    assert model.dof == 8 and len(model.couplings) == 1
    module = eomgen.derive(model, ("dtau", "dqdd", "dg_dq")).lambdify().module
    pm = pin.buildModelFromUrdf(str(path))
    T, c = (np.array(x, dtype=float) for x in coupling_map(model))
    rng = np.random.default_rng(12)
    for _ in range(3):
        q = np.append(rng.uniform(-1.5, 1.5, 7), rng.uniform(0, 0.04))
        v, u = rng.normal(size=(2, 8))
        dtau, dg, forward = reference(pm, T, T @ q + c.ravel(), v, u)
        for ours, theirs in zip(module.inverse_dynamics_derivatives(q, v, u), dtau):
            assert relative(ours, theirs) <= 1e-10
        assert relative(module.gravity_derivative(q), dg) <= 1e-10
        for ours, theirs in zip(module.forward_dynamics_derivatives(q, v, u), forward):
            assert relative(ours, theirs) <= 1e-10
