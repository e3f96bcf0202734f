"""Universal joints (eomgen.model.joints.universal) read from YAML against Pinocchio's
JointModelUniversal(x, y) in a model built by hand: M, h, τ, g, the ABA's q̈, the leaf link's
world-aligned and body Jacobians in every code backend; ∂τ/∂q, ∂τ/∂v, ∂q̈/∂q, ∂q̈/∂v against
Pinocchio's derivative algorithms on the same mechanism written as two revolute joints (its
own on JointModelUniversal miss the turning S: :func:`expected`); integrate, difference and
neutral; locking the joint by its name; an axis other than the shaft 0 0 1 refused in one line.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedError
from eomgen.model import lock_joints
from eomgen.model.configuration import difference, integrate, neutral
from eomgen.numeric.pinocchio import to_pinocchio
from support import relative
from support.extras import need, skip_backend
from support.generated import generated

pin = need("pinocchio", reason="the universal joint is checked against Pinocchio's")

#: base → universal 'cross' (offset, turned) → arm1 → revolute 'elbow' (offset, skew axis) → arm2.
ROBOT = """
name: cardan_arm
gravity: [0.3, -0.2, -9.81]
links:
  - name: base
  - name: arm1
    mass: 1.3
    com: [0.05, -0.02, 0.21]
    inertia: {ixx: 0.031, iyy: 0.027, izz: 0.012, ixy: 0.002, ixz: -0.003, iyz: 0.001}
  - name: arm2
    mass: 0.8
    com: [0.12, 0.03, -0.04]
    inertia: {ixx: 0.011, iyy: 0.019, izz: 0.016, ixy: -0.001, ixz: 0.0015, iyz: 0.0025}
joints:
  - name: cross
    type: universal
    parent: base
    child: arm1
    origin: {xyz: [0.1, -0.2, 0.3], rpy: [0.3, -0.5, 0.7]}
  - name: elbow
    type: revolute
    parent: arm1
    child: arm2
    origin: {xyz: [0.02, 0.04, 0.42], rpy: [-0.2, 0.1, 0.4]}
    axis: [0.36, 0.48, 0.8]
"""

OUTPUTS = ("M", "h", "tau", "g", "qdd_aba", "J_f", "Jb_f",
           "dtau_dq", "dtau_dqd", "dqdd_dq", "dqdd_dqd")


def write(folder, text):
    path = folder / "cardan_arm.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def pinocchio_model(universal=True):
    """The robot of :data:`ROBOT`, written again with Pinocchio's joint models: the universal
    joint a JointModelUniversal(x, y), or (``universal=False``) two revolute joints about x
    and the turned y with no body between them."""
    pm = pin.Model()
    X, Y = np.eye(3)[0], np.eye(3)[1]
    joints = (("cross", [0.1, -0.2, 0.3], [0.3, -0.5, 0.7], 1.3, [0.05, -0.02, 0.21],
               [[0.031, 0.002, -0.003], [0.002, 0.027, 0.001], [-0.003, 0.001, 0.012]], "arm1"),
              ("elbow", [0.02, 0.04, 0.42], [-0.2, 0.1, 0.4], 0.8, [0.12, 0.03, -0.04],
               [[0.011, -0.001, 0.0015], [-0.001, 0.019, 0.0025], [0.0015, 0.0025, 0.016]],
               "arm2"))
    parent = 0
    for name, xyz, rpy, mass, com, inertia, link in joints:
        placement = pin.SE3(pin.rpy.rpyToMatrix(np.array(rpy)), np.array(xyz))
        if name == "elbow":
            parent = pm.addJoint(parent, pin.JointModelRevoluteUnaligned(
                np.array([0.36, 0.48, 0.8])), placement, name)
        elif universal:
            parent = pm.addJoint(parent, pin.JointModelUniversal(X, Y), placement, name)
        else:
            parent = pm.addJoint(parent, pin.JointModelRevoluteUnaligned(X), placement,
                                 f"{name}_rx")
            parent = pm.addJoint(parent, pin.JointModelRevoluteUnaligned(Y),
                                 pin.SE3.Identity(), f"{name}_ry")
        pm.appendBodyToJoint(parent, pin.Inertia(mass, np.array(com), np.array(inertia)),
                             pin.SE3.Identity())
        pm.addBodyFrame(link, parent, pin.SE3.Identity(), 0)
    pm.gravity = pin.Motion(np.array([0.3, -0.2, -9.81]), np.zeros(3))
    return pm


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    folder = tmp_path_factory.mktemp("universal")
    (folder / "numpy").mkdir()
    (folder / "every").mkdir()
    return eomgen.load(write(folder, ROBOT)), pinocchio_model(), folder


@pytest.fixture(scope="module")
def numpy_module(robots):
    model, pm, folder = robots
    calls, modules = generated(model, OUTPUTS, folder / "numpy", backends=("numpy",))
    return pm, calls, modules["numpy"]


@pytest.fixture(scope="module")
def every_backend(robots):
    """The compiled and traced backends (a C compile each: slow)."""
    model, pm, folder = robots
    calls, modules = generated(model, OUTPUTS, folder / "every")
    return pm, calls, modules["numpy"]


def states(count=3, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield rng.uniform(-np.pi, np.pi, 3), rng.normal(size=3), rng.normal(size=3)


def expected(pm, frames, q, v, a):
    """``(function, inputs, Pinocchio's value)`` of every function of :data:`OUTPUTS`. The
    derivatives come from the chain of two revolute joints (Pinocchio 4.1's derivative
    algorithms do not follow a JointModelUniversal's S turning with q2: their ∂τ/∂q differs
    from a finite difference of its own rnea; :func:`test_the_chain_is_pinocchios_universal_joint`
    shows the chain is the same mechanism)."""
    data, chain = pm.createData(), pinocchio_model(universal=False)
    chain_data = chain.createData()
    upper = pin.crba(pm, data, q)
    tau = pin.rnea(pm, data, q, v, a).copy()
    dtau_dq, dtau_dv, _ = (d.copy() for d in pin.computeRNEADerivatives(
        chain, chain_data, q, v, a))
    pin.computeABADerivatives(chain, chain_data, q, v, tau)
    dqdd_dq, dqdd_dv = chain_data.ddq_dq.copy(), chain_data.ddq_dv.copy()
    pin.computeJointJacobians(pm, data, q)
    pin.updateFramePlacements(pm, data)
    ids = [pm.getFrameId(f) for f in frames]
    return [
        ("mass_matrix", (q,), np.triu(upper) + np.triu(upper, 1).T),
        ("nonlinear_effects", (q, v), pin.nonLinearEffects(pm, data, q, v).copy()),
        ("inverse_dynamics", (q, v, a), tau),
        ("gravity_vector", (q,), pin.computeGeneralizedGravity(pm, data, q).copy()),
        ("forward_dynamics_aba", (q, v, tau), pin.aba(pm, data, q, v, tau).copy()),
        ("frame_jacobians", (q,), np.vstack([pin.getFrameJacobian(
            pm, data, f, pin.LOCAL_WORLD_ALIGNED) for f in ids])),
        ("frame_body_jacobians", (q,), np.vstack([pin.getFrameJacobian(
            pm, data, f, pin.LOCAL) for f in ids])),
        ("inverse_dynamics_derivative_q", (q, v, a), dtau_dq),
        ("inverse_dynamics_derivative_qd", (q, v, a), dtau_dv),
        ("forward_dynamics_derivative_q", (q, v, tau), dqdd_dq),
        ("forward_dynamics_derivative_qd", (q, v, tau), dqdd_dv)]


def test_the_chain_is_pinocchios_universal_joint():
    """Pinocchio's two revolute joints (x, then the turned y, nothing between) and its
    JointModelUniversal(x, y) have one M, τ and q̈; the chain's ∂τ/∂q, ∂τ/∂v, ∂q̈/∂q, ∂q̈/∂v
    are central differences of the universal joint's rnea and aba (to the differences'
    truncation)."""
    pm, chain = pinocchio_model(), pinocchio_model(universal=False)
    data, chain_data = pm.createData(), chain.createData()
    step = 1e-6
    for q, v, a in states(seed=17):
        assert relative(pin.crba(chain, chain_data, q), pin.crba(pm, data, q)) < 1e-12
        tau = pin.rnea(pm, data, q, v, a).copy()
        assert relative(pin.rnea(chain, chain_data, q, v, a), tau) < 1e-12
        assert relative(pin.aba(chain, chain_data, q, v, tau), a) < 1e-10
        derivatives = [d.copy() for d in pin.computeRNEADerivatives(chain, chain_data, q, v, a)]
        pin.computeABADerivatives(chain, chain_data, q, v, tau)
        derivatives += [chain_data.ddq_dq.copy(), chain_data.ddq_dv.copy()]
        for k, e in enumerate(np.eye(3) * step):
            columns = [pin.rnea(pm, data, q + e, v, a) - pin.rnea(pm, data, q - e, v, a),
                       pin.rnea(pm, data, q, v + e, a) - pin.rnea(pm, data, q, v - e, a), None,
                       pin.aba(pm, data, q + e, v, tau) - pin.aba(pm, data, q - e, v, tau),
                       pin.aba(pm, data, q, v + e, tau) - pin.aba(pm, data, q, v - e, tau)]
            for derivative, column in zip(derivatives, columns):
                if column is not None:
                    assert relative(derivative[:, k], column / (2 * step)) < 1e-6


def test_layout_is_pinocchios(robots):
    """NQ = NV = 3, the universal joint's entries ``cross_rx``, ``cross_ry`` where Pinocchio
    has its (q1, q2), the joint recorded as one (locked and reduced by its name)."""
    model, pm, _ = robots
    assert (model.nq, model.dof) == (pm.nq, pm.nv) == (3, 3)
    assert model.joint_names == model.configuration_names == ("cross_rx", "cross_ry", "elbow")
    assert model.compound_joints == (("universal", "cross"),)
    assert model.quaternion_joints == ()
    assert np.array_equal(neutral(model), pin.neutral(pm))


def check_backend(generated_backends, backend):
    pm, calls, namespace = generated_backends
    if backend not in calls:
        skip_backend(backend)
    for q, v, a in states(seed=3):
        for function, inputs, value in expected(pm, namespace["FRAME_NAMES"], q, v, a):
            got = calls[backend](function, *inputs).reshape(value.shape)
            assert relative(got, value) < 1e-10, f"{backend} {function}"


def test_numpy_equals_pinocchio(numpy_module):
    check_backend(numpy_module, "numpy")


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["fast", "casadi", "jax", "torch"])
def test_every_backend_equals_pinocchio(every_backend, backend):
    check_backend(every_backend, backend)


def test_integrate_and_difference_equal_pinocchio(robots):
    model, pm, _ = robots
    for q, v, _ in states(seed=13):
        q1 = pin.integrate(pm, q, 0.7 * v)
        assert relative(integrate(q, v, 0.7, model), q1) < 1e-12
        assert relative(difference(q, q1, model), pin.difference(pm, q, q1)) < 1e-12


def test_locking_the_joint_by_name_keeps_pinocchios_pose(robots):
    """``cross`` locked at (q1, q2): the elbow's M and g are Pinocchio's with the universal
    joint held there (the kind's pose placed at the first virtual joint)."""
    model, pm, _ = robots
    locked = lock_joints(model, {"cross": (0.4, -1.1)})
    assert locked.joint_names == ("elbow",) and locked.compound_joints == ()
    data, reference = pm.createData(), to_pinocchio(locked)
    q = np.array([0.4, -1.1, 0.9])
    assert relative(reference.crba(q[2:]), pin.crba(pm, data, q)[2:, 2:]) < 1e-12
    g = pin.computeGeneralizedGravity(pm, data, q)[2:]
    assert relative(reference.rnea(q[2:], [0.0], [0.0]), g) < 1e-12


def test_an_axis_other_than_the_shaft_is_refused_in_one_line(tmp_path):
    text = ROBOT.replace("    origin: {xyz: [0.1, -0.2, 0.3], rpy: [0.3, -0.5, 0.7]}",
                         "    origin: {xyz: [0.1, -0.2, 0.3], rpy: [0.3, -0.5, 0.7]}\n"
                         "    axis: [1, 0, 0]", 1)
    with pytest.raises(UnsupportedError) as error:
        eomgen.load(write(tmp_path, text))
    message = str(error.value)
    assert "\n" not in message
    assert "cardan_arm.yaml" in message and "joint 'cross' axis" in message
    assert "must be 0 0 1" in message
