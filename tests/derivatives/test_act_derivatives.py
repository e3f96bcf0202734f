"""The derivatives of forward_dynamics_act (issue 41, for MPC): ``forward_dynamics_act_derivatives``
(∂(q̈, act_dot)/∂(q, q̇, ctrl, act) side by side), ``state_matrix_act`` and
``input_matrix_act`` (A, B of ẋ = f(x, ctrl), x = (q, q̇, act)).

References: central differences of the generated forward_dynamics_act (along eomgen's
``integrate`` for a ball joint) and of MuJoCo's own ``qacc_smooth`` and ``act_dot``
(``mj_forward``, contacts off, ``d.act`` set; not ``mjd_transitionFD``, whose Euler step is
implicit in the damping). The model: a filterexact position servo, a filter with a ctrlrange
and ``actearly``, an integrator with ``actearly`` and an ``actrange`` that clamps it, a DC
motor with inductance (its current a state, back-EMF, a rate limit) on a fixed tendon and
one on a joint, a PID with an integral gain and a motor without a state; states with
controls beyond ctrlrange, activations beyond actrange and currents within and beyond the
rate limit. Then a ball joint under a filter; (slow) every code backend gives the NumPy
module's.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model.configuration import integrate
from support import model_states, relative
from support.derivatives import results
from support.extras import need
from support.generated import generated

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import model_from_mujoco  # noqa: E402
from eomgen.parsers.mjcf.convert import layout, mujoco_dynamics, to_mujoco  # noqa: E402

OUTPUTS = ("xd_act", "dxd_act", "A_act", "B_act")
FUNCTIONS = ["forward_dynamics_act", "forward_dynamics_act_derivatives", "state_matrix_act",
             "input_matrix_act"]

ARM = """<mujoco model="actarm"><option timestep="0.004" gravity="0.3 -0.2 -9.81">
<flag contact="disable"/></option><worldbody>
<body><joint name="j1" axis="0 1 0.2" damping="0.05" stiffness="2"/>
 <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/>
 <body pos=".3 0 0"><joint name="j2" axis="0 1 0" armature="0.01"/>
  <geom type="capsule" size=".04" fromto="0 0 0 .3 0 .1"/>
  <body pos=".3 0 .1"><joint name="j3" type="slide" axis="1 0 0"/><geom size=".05"/>
   <body pos=".05 0 0"><joint name="j4" axis="1 0 0" damping="0.1"/>
    <geom type="capsule" size=".02" fromto="0 0 0 0 .2 0"/></body></body>
 </body></body></worldbody>
<tendon><fixed name="t"><joint joint="j2" coef="0.5"/><joint joint="j3" coef="-1"/></fixed>
</tendon><actuator>
 <position name="pf" joint="j1" kp="20" kv="1" timeconst="0.1"/>
 <general name="f" joint="j2" dyntype="filter" dynprm="0.05" gainprm="3" ctrlrange="-1 1"
   ctrllimited="true" actearly="true"/>
 <general name="i" joint="j4" dyntype="integrator" gainprm="2" biastype="affine"
   biasprm="0.1 -1 -0.3" actearly="true" actlimited="true" actrange="-0.5 0.5"/>
 <dcmotor name="dc" tendon="t" resistance="1.5" motorconst="0.04 0.06" inductance="0.003 0"
   saturation="0.5 0 30" ctrlrange="-12 12" ctrllimited="true" gear="2"/>
 <dcmotor name="dj" joint="j1" resistance="2" motorconst="0.05" gear="3" inductance="0 0.01"/>
 <pid name="pid" joint="j3" kp="8" kv="0.3" ki="2" input="pos" ctrlrange="-1 1"
   ctrllimited="true" forcerange="-3 3" forcelimited="true"/>
 <motor name="m" joint="j4" gear="2"/>
</actuator></mujoco>"""

BALL = """<mujoco model="ballact"><option><flag contact="disable"/></option><worldbody>
<body pos="0 0 1"><joint name="b1" type="ball" armature="0.05" damping="0.3" stiffness="2"/>
 <geom type="capsule" size=".05" fromto="0 0 0 .4 0 .1"/>
 <body pos=".4 0 .1"><joint name="h1" axis="0 1 0" armature="0.02" damping="0.1"/>
  <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/></body></body></worldbody>
<actuator><position joint="h1" kp="3" kv="0.2"/>
 <general joint="h1" dyntype="filter" dynprm="0.3" gainprm="2" actearly="true"/></actuator>
</mujoco>"""


def compiled(xml, name):
    m = mujoco.MjModel.from_xml_string(xml)
    model = model_from_mujoco(m, f"{name}.xml")
    return m, model, eomgen.derive(model, outputs=OUTPUTS).lambdify().module


@pytest.fixture(scope="module")
def arm():
    return compiled(ARM, "actarm")


def differences(f, x, h=1e-6):
    return np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


def states(m, model, rng, count):
    """Random states, controls (some beyond ctrlrange) and activations (some beyond actrange);
    in every other one motor dc's current within its rate limit (30 A/s, T = 2 ms)."""
    dc = model.controls[3]
    R, K = (float(x) for x in dc.motor)
    for k in range(count):
        q, qd = rng.uniform(-1, 1, m.nq), rng.uniform(-2, 2, m.nv)
        ctrl, act = rng.uniform(-2, 2, m.nu), rng.uniform(-1, 1, m.na)
        ctrl[3] *= 8
        if k % 2:  # act index 3 is dc's current; its velocity 2 (0.5 qd2 - qd3)
            velocity = 2 * (0.5 * qd[1] - qd[2])
            act[3] = (np.clip(ctrl[3], -12, 12) - K * velocity) / R + 0.02 * np.sin(k)
        yield q, qd, ctrl, act


def split(x, sizes):
    return np.split(x, np.cumsum(sizes)[:-1])


def test_the_activation_dynamics_are_what_the_docstring_says(arm):
    _, model, module = arm
    assert [(c.name, c.dynamics, c.early is not None) for c in model.controls] == [
        ("pf", "filterexact", False), ("f", "filter", True), ("i", "integrator", True),
        ("dc", "dcmotor", True), ("dj", "dcmotor", True), ("pid", "pid", False),
        ("m", None, False)]
    assert module.ACTIVATION_NAMES == ("pf", "f", "i", "dc", "dj", "pid")


def test_the_jacobian_is_central_differences_of_forward_dynamics_act(arm):
    m, model, module = arm
    sizes = (m.nq, m.nv, m.nu, m.na)
    worst = 0.0
    for x in states(m, model, np.random.default_rng(3), 6):
        J = module.forward_dynamics_act_derivatives(*x)
        assert J.shape == (m.nv + m.na, 2 * m.nv + m.nu + m.na)
        numeric = differences(
            lambda y: module.forward_dynamics_act(*split(y, sizes)).ravel(), np.concatenate(x))
        worst = max(worst, relative(J, numeric))
    assert worst <= 1e-6, worst


def mujoco_rates(m, d, q, qd, ctrl, act):
    d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = q, qd, ctrl, act
    mujoco.mj_forward(m, d)
    return np.r_[d.qacc_smooth, d.act_dot]


def test_the_jacobian_is_central_differences_of_mujocos_qacc_smooth_and_act_dot(arm):
    m, model, module = arm
    d = mujoco.MjData(m)
    sizes = (m.nq, m.nv, m.nu, m.na)
    worst, held = 0.0, 0
    for x in states(m, model, np.random.default_rng(5), 6):
        J = module.forward_dynamics_act_derivatives(*x)
        numeric = differences(lambda y: mujoco_rates(m, d, *split(y, sizes)),
                              np.concatenate(x))
        held += abs(mujoco_rates(m, d, *x)[m.nv + 3]) == 30  # dc's rate limit
        worst = max(worst, relative(J, numeric))
    assert worst <= 1e-6, worst
    assert held == 3


def test_actearly_puts_the_rates_control_slope_into_the_accelerations(arm):
    """With ``actearly`` the filter f pushes q̈ as soon as its control moves: ∂q̈/∂ctrl_f =
    M_a⁻¹ gain α / T ≠ 0 (without it the column would be zero, the force following act)."""
    m, model, module = arm
    q, qd, ctrl, act = next(states(m, model, np.random.default_rng(8), 1))
    ctrl[1], act[1] = 0.3, 0.1  # f inside its ctrlrange
    J = module.forward_dynamics_act_derivatives(q, qd, ctrl, act)
    column, alpha = J[:m.nv, 2 * m.nv + 1], float(model.controls[1].early)
    slope = 3 * alpha / float(model.controls[1].timeconst)  # gain α ∂act_dot/∂ctrl
    M = mujoco_dynamics(m, layout(m, model), q, qd)["M_a"]  # MuJoCo's, armature included
    assert relative(column, np.linalg.solve(M, slope * np.eye(m.nv)[1])) < 1e-12


def test_the_state_space_pair_holds_the_jacobians_blocks(arm):
    m, model, module = arm
    nv, nu, na = m.nv, m.nu, m.na
    x = next(states(m, model, np.random.default_rng(9), 1))
    J = module.forward_dynamics_act_derivatives(*x)
    A, B = module.state_matrix_act(*x), module.input_matrix_act(*x)
    assert A.shape == (2 * nv + na, 2 * nv + na) and B.shape == (2 * nv + na, nu)
    top = np.hstack([np.zeros((nv, nv)), np.eye(nv), np.zeros((nv, na))])
    state = np.hstack([J[:, :2 * nv], J[:, 2 * nv + nu:]])
    assert np.array_equal(A, np.vstack([top, state]))
    assert np.array_equal(B, np.vstack([np.zeros((nv, nu)), J[:, 2 * nv:2 * nv + nu]]))


@pytest.fixture(scope="module")
def ball():
    return compiled(BALL, "ballact")


def test_a_ball_joint_is_differentiated_along_the_tangent(ball):
    """Against eomgen's own q̈ and act_dot along ``integrate`` and against MuJoCo's (this
    model's velocities are MuJoCo's: no free joint)."""
    m, model, module = ball
    d, lay = mujoco.MjData(m), layout(m, model)
    ctrl, act, worst = np.array([0.4, -0.8]), np.array([0.7]), 0.0
    for q, v in model_states(model, count=2, seed=4):
        J = module.forward_dynamics_act_derivatives(q, v, ctrl, act)
        for f in (lambda q_, v_, u, a: module.forward_dynamics_act(q_, v_, u, a).ravel(),
                  lambda q_, v_, u, a: mujoco_rates(m, d, *to_mujoco(lay, q_, v_), u, a)):
            along = np.column_stack([
                (f(integrate(q, 1e-6 * e, model=model), v, ctrl, act)
                 - f(integrate(q, -1e-6 * e, model=model), v, ctrl, act)) / 2e-6
                for e in np.eye(model.dof)])
            rest = differences(lambda y: f(q, *split(y, (model.dof, 2, 1))),
                               np.r_[v, ctrl, act])
            worst = max(worst, relative(J, np.hstack([along, rest])))
    assert worst <= 1e-6, worst


@pytest.mark.slow
def test_every_code_backend_gives_the_numpy_derivatives(arm, tmp_path):
    m, model, _ = arm
    _, modules = generated(model, FUNCTIONS[1:], tmp_path)
    x = next(states(m, model, np.random.default_rng(21), 1))
    reference = {f: results("numpy", modules["numpy"], f, *x) for f in FUNCTIONS[1:]}
    for backend, module in modules.items():
        for f in FUNCTIONS[1:]:
            for ours, theirs in zip(results(backend, module, f, *x), reference[f]):
                assert np.allclose(np.reshape(ours, theirs.shape), theirs, rtol=1e-12,
                                   atol=1e-12), (backend, f)


COUPLED = """<mujoco model="coupledact"><option><flag contact="disable"/></option><worldbody>
<body><joint name="j1" axis="0 0 1" damping="0.2" armature="0.03"/>
 <geom type="capsule" size=".04" fromto="0 0 0 .4 0 0" mass="1"/>
 <body pos=".4 0 0"><joint name="j2" axis="0 1 .3" armature="0.02" stiffness="2"/>
  <geom type="capsule" size=".03" fromto="0 0 0 .3 0 .1" mass=".6"/>
  <body pos=".3 0 .1"><joint name="j3" axis="1 0 0"/>
   <geom type="capsule" size=".02" fromto="0 0 0 0 .2 0" mass=".2"/></body></body></body>
</worldbody><equality><joint joint1="j2" joint2="j1" polycoef="0.1 -0.5 0 0 0"/></equality>
<actuator><general joint="j2" dyntype="filter" dynprm="0.2" gainprm="3" biastype="affine"
  biasprm="0 -1 -0.1" actearly="true"/><intvelocity joint="j3" kp="4" actrange="-1 1"/>
 <motor joint="j1" gear="2"/></actuator></mujoco>"""


def test_a_coupled_model_is_differentiated_in_its_independent_coordinates():
    m, model, module = compiled(COUPLED, "coupledact")
    assert model.joint_names == ("j1", "j3")
    rng, worst = np.random.default_rng(6), 0.0
    for _ in range(3):
        x = (rng.uniform(-1, 1, 2), rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 3),
             rng.uniform(-1.5, 1.5, 2))
        J = module.forward_dynamics_act_derivatives(*x)
        assert J.shape == (2 + 2, 2 + 2 + 3 + 2)
        numeric = differences(
            lambda y: module.forward_dynamics_act(*split(y, (2, 2, 3, 2))).ravel(),
            np.concatenate(x))
        worst = max(worst, relative(J, numeric))
    assert worst <= 1e-6, worst
