"""Derivatives of the drives' dynamics (armature, viscous and Coulomb friction) on models with
quaternion joints (issue 25): ``drive_inverse_dynamics_derivatives`` and
``drive_forward_dynamics_derivatives`` of a free-flying trunk with a two-hinge leg and of a
ball-jointed arm, ∂/∂q along the tangent (NV columns), as Pinocchio's.

References: Pinocchio 4 reading the same MJCF text (``JointModelFreeFlyer``,
``JointModelSpherical``), with ``model.armature`` set to the hinges' armature (0 on the
quaternion joints, which carry no drive): ``computeABADerivatives`` at the effort τ − τ_f(q̇)
the rigid bodies receive, the smoothed friction's slope d + f/w (1 − tanh²(q̇/w)) added from its
formula, and ``computeRNEADerivatives`` + diag(d); central differences along eomgen's
``integrate`` (Pinocchio's) of the generated ``drive_inverse_dynamics`` and of the drives'
forward dynamics solved from the generated ``drive_mass_matrix`` and ``inverse_dynamics``;
(slow) every backend against the NumPy module.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model import joint_actuators
from eomgen.model.configuration import integrate
from support.generated import BACKENDS, generated
from support.extras import need

pin = need("pinocchio", reason="checked against Pinocchio's derivatives")
need("mujoco", reason="the models are MJCF, read by MuJoCo's compiler")

GRAVITY = np.array([0.3, -0.2, -9.81])
DRIVE = 'armature="{a}" damping="{d}" frictionloss="{f}"'
#: a free-flying trunk with a two-hinge leg (NQ 9, NV 8), a drive on every hinge
HOPPER = f"""<mujoco model="hopper2"><option gravity="0.3 -0.2 -9.81"/><worldbody>
<body name="torso" pos="0 0 1"><freejoint name="root"/>
<inertial pos="0.01 -0.02 0.03" mass="4" fullinertia="0.2 0.3 0.25 0.01 -0.02 0.015"/>
<body name="thigh" pos="0.1 0.15 -0.1" quat="0.9 0.1 0.3 0.2">
<joint name="hip" type="hinge" axis="0 1 0.2" {DRIVE.format(a=0.05, d=0.3, f=0.2)}/>
<inertial pos="0 0.01 -0.2" mass="1.2" fullinertia="0.02 0.025 0.01 0.001 0.002 -0.001"/>
<body name="shank" pos="0 0.02 -0.4"><joint name="knee" type="hinge" axis="1 0 0.3" {DRIVE.format(a=0.08, d=0.2, f=0.1)}/>
<inertial pos="0.01 0 -0.2" mass="0.8" diaginertia="0.01 0.012 0.004"/>
</body></body></body></worldbody></mujoco>"""
#: a ball shoulder and a driven hinge elbow (NQ 5, NV 4)
BALL_ARM = f"""<mujoco model="ball_arm"><option gravity="0.3 -0.2 -9.81"/><worldbody>
<body name="upper" pos="0.1 0 0.2" quat="0.9 0.1 0.3 0.2">
<joint name="shoulder" type="ball" pos="0 0 0.05"/>
<inertial pos="0.02 0.01 -0.2" mass="1.2" fullinertia="0.02 0.025 0.01 0.001 0.002 -0.001"/>
<body name="fore" pos="0 0.05 -0.4"><joint name="elbow" type="hinge" axis="0.3 1 0" {DRIVE.format(a=0.06, d=0.25, f=0.15)}/>
<inertial pos="0.01 0 -0.2" mass="0.8" diaginertia="0.01 0.012 0.004"/></body></body>
</worldbody></mujoco>"""
ROBOTS = {"hopper2": HOPPER, "ball_arm": BALL_ARM}
INVERSE, FORWARD = "drive_inverse_dynamics_derivatives", "drive_forward_dynamics_derivatives"
FUNCTIONS = [INVERSE, FORWARD, "drive_inverse_dynamics", "drive_mass_matrix",
             "inverse_dynamics"]


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def case(request, tmp_path_factory):
    """(model, NumPy module, Pinocchio model with the armature, drive values (a, d, f, w))."""
    folder = tmp_path_factory.mktemp(request.param)
    path = folder / f"{request.param}.xml"
    path.write_text(ROBOTS[request.param], encoding="utf-8")
    model = eomgen.load(path)
    assert model.quaternion_joints
    _, modules = generated(model, FUNCTIONS, folder, backends=("numpy",))
    pm = pin.buildModelFromMJCF(str(path))
    pm.gravity = pin.Motion(GRAVITY, np.zeros(3))
    assert (pm.nq, pm.nv) == (model.nq, model.dof)
    drives = joint_actuators(model)
    a, d, f = (np.array([float(getattr(x, name)) for x in drives])
               for name in ("armature", "damping", "friction"))
    w = np.array([float(x.friction_width) for x in drives])
    hinges = [k for k, name in enumerate(model.joint_names) if name in ("hip", "knee", "elbow")]
    assert np.all(a[hinges] > 0) and np.count_nonzero(a) == len(hinges)  # none on quaternions
    pm.armature = a
    return model, modules["numpy"], pm, (a, d, f, w)


def states(pm, count, seed):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


def relative(ours, theirs):
    return np.abs(ours - theirs).max() / max(1.0, np.abs(theirs).max())


def test_drive_derivatives_equal_pinocchios_along_the_tangent(case):
    model, module, pm, (a, d, f, w) = case
    data = pm.createData()
    for q, v, u in states(pm, 2, seed=7):
        # forward: Pinocchio's ABA derivatives (armature included) at the effort τ − τ_f
        effort = u - d * v - f * np.tanh(v / w)
        pin.computeABADerivatives(pm, data, q, v, effort)
        Minv = np.triu(data.Minv) + np.triu(data.Minv, 1).T
        slope = d + f / w * (1 - np.tanh(v / w) ** 2)
        expected = (data.ddq_dq, data.ddq_dv - Minv * slope, Minv)     # Minv @ diag(slope)
        got = module[FORWARD](q, v, u)
        M_a = pin.crba(pm, data, q)
        np.testing.assert_allclose(got[2] @ (np.triu(M_a) + np.triu(M_a, 1).T), np.eye(pm.nv),
                                   atol=1e-10)
        for name, ours, theirs in zip(("dq", "dv", "Minv_a"), got, expected):
            assert ours.shape == (pm.nv, pm.nv)
            assert relative(ours, theirs) <= 1e-10, name
        # inverse: Pinocchio's RNEA derivatives + diag(d)
        pin.computeRNEADerivatives(pm, data, q, v, u)
        got = module[INVERSE](q, v, u)
        for name, ours, theirs in zip(("dq", "dv"), got, (data.dtau_dq, data.dtau_dv + np.diag(d))):
            assert relative(ours, theirs) <= 1e-10, name


def test_drive_derivatives_are_central_differences_along_integrate(case):
    model, module, pm, (a, d, f, w) = case
    h, n = 1e-6, pm.nv
    tau_a, M_a, tau = (module[x] for x in ("drive_inverse_dynamics", "drive_mass_matrix",
                                            "inverse_dynamics"))

    def forward(q, v, u):  # the drives' forward dynamics, solved from generated M_a and tau
        return np.linalg.solve(M_a(q), u - tau(q, v, np.zeros(n)) - d * v - f * np.tanh(v / w))

    def columns(g, x, along):
        steps = np.eye(n) * h
        if along:
            pairs = [(g(integrate(x, e, model=model)), g(integrate(x, -e, model=model)))
                     for e in steps]
        else:
            pairs = [(g(x + e), g(x - e)) for e in steps]
        return np.stack([(p - m) / (2 * h) for p, m in pairs], axis=1)

    for q, v, u in states(pm, 1, seed=8):
        dq, dv = module[INVERSE](q, v, u)
        np.testing.assert_allclose(dq, columns(lambda x: tau_a(x, v, u), q, True), atol=1e-6)
        np.testing.assert_allclose(dv, columns(lambda x: tau_a(q, x, u), v, False), atol=1e-6)
        dq, dv, Minv = module[FORWARD](q, v, u)
        np.testing.assert_allclose(dq, columns(lambda x: forward(x, v, u), q, True), atol=1e-6)
        np.testing.assert_allclose(dv, columns(lambda x: forward(q, x, u), v, False), atol=1e-6)
        np.testing.assert_allclose(Minv, columns(lambda x: forward(q, v, x), u, False),
                                   atol=1e-6)


@pytest.mark.slow  # a C compile and three array libraries
def test_every_backend_gives_the_numpy_modules_drive_derivatives(tmp_path):
    path = tmp_path / "ball_arm.xml"
    path.write_text(BALL_ARM, encoding="utf-8")
    pm = pin.buildModelFromMJCF(str(path))
    single = ["drive_inverse_dynamics_derivative_qd", "drive_forward_dynamics_derivative_q",
              "drive_forward_dynamics_derivative_qd", "drive_inverse_mass_matrix"]
    calls, _ = generated(eomgen.load(path), single, tmp_path, BACKENDS)
    for q, v, u in states(pm, 1, seed=9):
        for function in single:
            args = (q,) if function == "drive_inverse_mass_matrix" else (q, v, u)
            expected = calls["numpy"](function, *args)
            assert expected.shape == (pm.nv, pm.nv)
            for backend, call in calls.items():
                np.testing.assert_allclose(call(function, *args).reshape(expected.shape),
                                           expected, rtol=1e-11, atol=1e-11,
                                           err_msg=f"{backend} {function}")
