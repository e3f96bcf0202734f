"""Planar and helical joints (eomgen.model.joints.planar, .helical): the generated M, h, τ, g,
forward dynamics, a leaf link's Jacobians and the derivatives of τ and q̈ against Pinocchio's
JointModelPlanar and JointModelHelicalUnaligned, q (NQ) and v (NV) passed unchanged, in every
code backend; integrate, difference and neutral against Pinocchio's.

Pinocchio's models are built by hand from the same list of joints (pin.Model.addJoint,
appendBodyToJoint), not through eomgen's adapter or its chains (a planar joint's three virtual
joints). A helical joint is one joint of the tree (no coupling), so both chains have the ABA's
q̈ too, and the screw chain's joint torque regressor is Pinocchio's.
"""

from __future__ import annotations

import numpy as np
import sympy as sp
import pytest

from eomgen.model import Joint, JointType, Link, Transform, build_model, mat3, vec3
from eomgen.model.configuration import difference, integrate, neutral
from support import relative
from support.extras import need, skip_backend
from support.generated import generated
from support.reference import random_inertial, random_rotation

pin = need("pinocchio", reason="planar and helical joints are checked against Pinocchio")

PITCH = 0.07  # m/rad
#: (name, type, parent joint index): a planar joint mid-chain, then a helical joint.
SCREW = (("j0", "revolute", -1), ("plane", "planar", 0), ("screw", "helical", 1),
         ("j3", "prismatic", 2))
#: The same without the helical joint.
PLANAR = (("j0", "revolute", -1), ("plane", "planar", 0), ("j2", "prismatic", 1))
SPECS = {"screw": SCREW, "planar": PLANAR}
GRAVITY = np.array([0.3, -0.2, -9.81])

#: The outputs both chains export in every backend. The quick test takes the screw chain's
#: first four in NumPy, its ABA's q̈ and its regressor (a derivation of ~5 s; the others take
#: ~15 s more).
OUTPUTS = ("M", "tau", "J_f", "Jb_f", "h", "g", "forward_dynamics", "Minv",
           "dtau_dq", "dtau_dqd", "dqdd_dq", "dqdd_dqd", "qdd_aba")
QUICK = OUTPUTS[:4] + ("qdd_aba", "Y")


def pinocchio_joint(kind, axis):
    return {"revolute": lambda: pin.JointModelRevoluteUnaligned(axis),
            "prismatic": lambda: pin.JointModelPrismaticUnaligned(axis),
            "planar": pin.JointModelPlanar,
            "helical": lambda: pin.JointModelHelicalUnaligned(axis, PITCH)}[kind]()


def pin_inertia(inertial):
    return pin.Inertia(float(inertial.mass), np.array([float(x) for x in inertial.com]),
                       np.array([[float(x) for x in row] for row in inertial.inertia]))


def robots(spec, seed=1, aligned=False):
    """The eomgen model (build_model: the planar joints become their chains) and Pinocchio's
    model built by hand from ``spec``: random joint placements, random unit axes (``aligned``:
    ±x, ±y or ±z of the joint frame; a planar joint's is the joint frame's z, its plane turned
    by the placement), every link with mass, each link a body frame."""
    rng = np.random.default_rng(seed)
    links, joints, ids = [Link("trunk", random_inertial(rng))], [], []
    pm = pin.Model()
    for name, kind, parent in spec:
        R, p = random_rotation(rng), rng.uniform(-0.5, 0.5, 3)
        axis = rng.normal(size=3)
        if aligned:
            axis = np.eye(3)[rng.integers(3)] * rng.choice([-1.0, 1.0])
        axis = np.array([0.0, 0.0, 1.0]) if kind == "planar" else axis / np.linalg.norm(axis)
        inertial = random_inertial(rng)
        links.append(Link(f"link_{name}", inertial))
        joints.append(Joint(name, JointType(kind),
                            "trunk" if parent < 0 else f"link_{spec[parent][0]}", f"link_{name}",
                            Transform(mat3(R.tolist()), vec3(p.tolist())), vec3(axis.tolist()),
                            pitch=PITCH if kind == "helical" else 0))
        jid = pm.addJoint(0 if parent < 0 else ids[parent], pinocchio_joint(kind, axis),
                          pin.SE3(R, p), name)
        pm.appendBodyToJoint(jid, pin_inertia(inertial), pin.SE3.Identity())
        pm.addBodyFrame(f"link_{name}", jid, pin.SE3.Identity(), 0)
        ids.append(jid)
    model = build_model("<test>", "kinds_chain", links, joints, gravity=GRAVITY.tolist())
    pm.gravity = pin.Motion(GRAVITY, np.zeros(3))
    return model, pm


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """The screw chain (a planar and a helical joint) in a NumPy module of :data:`QUICK`."""
    model, pm = robots(SCREW)
    calls, modules = generated(model, QUICK, tmp_path_factory.mktemp("screw"),
                               backends=("numpy",))
    return model, pm, calls["numpy"], modules["numpy"]


@pytest.fixture(scope="module", params=sorted(SPECS))
def every_backend(request, tmp_path_factory):
    """Both chains in every code backend (a C compile each: slow)."""
    model, pm = robots(SPECS[request.param])
    calls, modules = generated(model, OUTPUTS,
                               tmp_path_factory.mktemp(f"{request.param}_backends"))
    return request.param, model, pm, calls, modules["numpy"]


def states(pm, count=2, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


def symmetric(upper):
    return np.triu(upper) + np.triu(upper, 1).T


def expected(pm, frames, q, v, a):
    """``(function, inputs, Pinocchio's value)`` of every generated function at ``(q, v, a)``;
    ``frames``: the module's FRAME_NAMES (the leaf link)."""
    data = pm.createData()
    M = symmetric(pin.crba(pm, data, q))
    tau = pin.rnea(pm, data, q, v, a).copy()
    dtau_dq, dtau_dv, _ = (d.copy() for d in pin.computeRNEADerivatives(pm, data, q, v, a))
    pin.computeABADerivatives(pm, data, q, v, tau)
    dqdd_dq, dqdd_dv = data.ddq_dq.copy(), data.ddq_dv.copy()
    pin.computeJointJacobians(pm, data, q)
    pin.updateFramePlacements(pm, data)
    ids = [pm.getFrameId(f) for f in frames]
    values = [
        ("mass_matrix", (q,), M),
        ("nonlinear_effects", (q, v), pin.nonLinearEffects(pm, data, q, v).copy()),
        ("inverse_dynamics", (q, v, a), tau),
        ("gravity_vector", (q,), pin.computeGeneralizedGravity(pm, data, q).copy()),
        ("forward_dynamics", (q, v, tau), a),
        ("inverse_mass_matrix", (q,), symmetric(pin.computeMinverse(pm, data, q))),
        ("frame_jacobians", (q,), np.vstack([pin.getFrameJacobian(
            pm, data, f, pin.LOCAL_WORLD_ALIGNED) for f in ids])),
        ("frame_body_jacobians", (q,), np.vstack([pin.getFrameJacobian(
            pm, data, f, pin.LOCAL) for f in ids])),
        ("inverse_dynamics_derivative_q", (q, v, a), dtau_dq),
        ("inverse_dynamics_derivative_qd", (q, v, a), dtau_dv),
        ("forward_dynamics_derivative_q", (q, v, tau), dqdd_dq),
        ("forward_dynamics_derivative_qd", (q, v, tau), dqdd_dv),
        ("forward_dynamics_aba", (q, v, tau), pin.aba(pm, data, q, v, tau).copy())]
    return values


def test_layout_is_pinocchios(case):
    """NQ, NV, each joint's place in q and v, and the names of the entries: a planar joint's
    ``<name>_x, _y, _cos, _sin`` and ``<name>_vx, _vy, _wz``, a helical joint's one."""
    model, pm, _, namespace = case
    assert (model.nq, model.dof) == (pm.nq, pm.nv) == (namespace["NQ"], namespace["NV"])
    assert tuple(namespace["CONFIGURATION_NAMES"]) == model.configuration_names
    assert tuple(namespace["JOINT_NAMES"]) == model.joint_names
    for joint in pm.names[1:]:
        jid = pm.getJointId(joint)
        k, iq = pm.joints[jid].idx_v, pm.joints[jid].idx_q
        if joint == "plane":
            assert model.joint_names[k:k + 3] == ("plane_vx", "plane_vy", "plane_wz")
            assert model.configuration_names[iq:iq + 4] == (
                "plane_x", "plane_y", "plane_cos", "plane_sin")
        else:
            assert (model.joint_names[k], model.configuration_names[iq]) == (joint, joint)
    assert model.compound_joints == (("planar", "plane"),)
    assert model.couplings == ()
    assert {j.name: j.type for j in model.joints}["screw"] is JointType.HELICAL


def test_dynamics_equal_pinocchio(case):
    """M, τ, the ABA's q̈ and the leaf link's world-aligned and body Jacobians of the screw
    chain (the other outputs and the planar chain: every backend, below)."""
    _, pm, call, namespace = case
    checked = set()
    for q, v, a in states(pm, seed=5):
        for function, inputs, value in expected(pm, namespace["FRAME_NAMES"], q, v, a):
            if function in namespace:
                got = call(function, *inputs)
                assert got.shape == value.shape, function
                assert relative(got, value) < 1e-10, function
                checked.add(function)
    assert len(checked) == len(QUICK) - 1  # Y: below


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["numpy", "fast", "casadi", "jax", "torch"])
def test_every_backend_equals_pinocchio(every_backend, backend):
    """Every function of :func:`expected` in every code backend: M, h, τ, g, q̈ (Cholesky, and
    the ABA's for the planar chain), M⁻¹, the leaf link's world-aligned and body Jacobians,
    ∂τ/∂q, ∂τ/∂v, ∂q̈/∂q, ∂q̈/∂v, the ABA's q̈ (∂/∂q in tangent coordinates, as Pinocchio's). CasADi's module
    has no Cholesky forward_dynamics: its q̈ is M⁻¹ (τ − h), from its own functions."""
    name, _, pm, calls, namespace = every_backend
    if backend not in calls:
        skip_backend(backend)
    call = calls[backend]
    for q, v, a in states(pm, count=2, seed=3):
        for function, inputs, value in expected(pm, namespace["FRAME_NAMES"], q, v, a):
            if backend == "casadi" and function == "forward_dynamics":
                tau = inputs[2]
                got = call("inverse_mass_matrix", q) @ (tau - call("nonlinear_effects", q, v))
            else:
                got = call(function, *inputs).reshape(value.shape)
            assert relative(got, value) < 1e-10, f"{backend} {function}"


def test_regressor_equals_pinocchios(case):
    """Y(q, v, a) of the screw chain is Pinocchio's joint torque regressor, its columns the
    bodies' ten parameters in the same order (m, m c, I about the link origin), and Y π = τ
    with the links' parameters (eomgen's π for the chain's massless links is zero)."""
    model, pm, call, namespace = case
    for q, v, a in states(pm, seed=9):
        Y = call("regressor", q, v, a)
        Y_pin = pin.computeJointTorqueRegressor(pm, pm.createData(), q, v, a)
        assert Y.shape[0] == pm.nv
        links = [model.link_by_name[f"link_{name}"] for name in pm.names[1:]]
        pi = np.concatenate([pm.inertias[j].toDynamicParameters() for j in range(1, pm.njoints)])
        tau = pin.rnea(pm, pm.createData(), q, v, a)
        assert relative(Y_pin @ pi, tau) < 1e-10
        # eomgen's columns: ten per movable joint of the tree (the planar chain's massless
        # virtual links too), the body of each joint of Pinocchio's the last ten of its block
        names = list(namespace["JOINT_NAMES"])
        blocks = [names.index(n if n != "plane" else "plane_wz") for n in pm.names[1:]]
        mine = np.hstack([Y[:, 10 * k:10 * k + 10] for k in blocks])
        assert relative(mine, Y_pin) < 1e-10, [link.name for link in links]


@pytest.mark.parametrize("name", sorted(SPECS))
def test_integrate_difference_and_neutral_equal_pinocchio(name):
    rng = np.random.default_rng(11)
    model, pm = robots(SPECS[name])
    assert np.array_equal(neutral(model), pin.neutral(pm))
    for q, v, _ in states(pm, count=2, seed=13):
        dt = rng.uniform(0.1, 2.0)
        q1 = pin.integrate(pm, q, v * dt)
        assert relative(integrate(q, v, dt, model), q1) < 1e-12
        assert relative(difference(q, q1, model), v * dt) < 1e-10
        assert relative(difference(q, q1, model), pin.difference(pm, q, q1)) < 1e-10


#: Helical joints alone (with a revolute one between): the base regressor and the textbook.
HELIX = (("a", "helical", -1), ("b", "revolute", 0), ("c", "helical", 1))


def test_aligned_helical_joints_equal_pinocchio(tmp_path):
    """τ and g with helical joints about ±x, ±y, ±z of their frames, where the grouping of
    inertial parameters and the leaf's turned frame (Newton–Euler's leaf phases) apply: a
    helical joint's body keeps its mass and first moments (they slide with the screw)."""
    model, pm = robots(HELIX, seed=7, aligned=True)
    calls, _ = generated(model, ("tau", "g"), tmp_path, backends=("numpy",))
    data = pm.createData()
    for q, v, a in states(pm, count=2, seed=25):
        tau = calls["numpy"]("inverse_dynamics", q, v, a)
        assert relative(tau, pin.rnea(pm, data, q, v, a)) < 1e-10
        g = calls["numpy"]("gravity_vector", q)
        assert relative(g, pin.computeGeneralizedGravity(pm, data, q)) < 1e-10


@pytest.fixture(scope="module")
def helix(tmp_path_factory):
    model, pm = robots(HELIX, seed=4)
    calls, _ = generated(model, ("Y_base", "beta", "Y_SL_base", "C", "g"),
                         tmp_path_factory.mktemp("helix"), backends=("numpy",))
    return model, pm, calls["numpy"]


def test_base_regressors_give_pinocchios_torques(helix):
    """Y_base β = τ (Pinocchio's rnea) and Y_SL,base(q, q̇, q̇_r, q̈_r) β = M q̈_r + C q̇_r
    + g (Pinocchio's M, C, g), with Y_base of full column rank over random states: the grouping
    of a helical joint's parameters (only β (1 − k kᵀ) of its body's inertia crosses it) keeps
    the torques and leaves no dependent column."""
    model, pm, call = helix
    beta = call("base_parameters")
    data = pm.createData()
    rows = []
    for q, v, a in states(pm, count=12, seed=21):
        Y_base = call("base_regressor", q, v, a)
        rows.append(Y_base)
        assert relative(Y_base @ beta, pin.rnea(pm, data, q, v, a)) < 1e-10
        qd_r = a[::-1].copy()
        M = symmetric(pin.crba(pm, data, q))
        C = pin.computeCoriolisMatrix(pm, data, q, v)
        target = M @ a + C @ qd_r + pin.computeGeneralizedGravity(pm, data, q)
        assert relative(call("slotine_li_base_regressor", q, v, qd_r, a) @ beta, target) < 1e-10
    s = np.linalg.svd(np.vstack(rows), compute_uv=False)
    assert np.sum(s > 1e-9 * s[0]) == len(beta)


def test_textbook_derivation_equals_pinocchio():
    """The teaching derivation (a helical joint's ω along its axis, its slide in the pose) gives
    Pinocchio's M, C q̇ + g."""
    from eomgen.symbolic.textbook import textbook_derivation
    model, pm = robots(HELIX[:2], seed=4)
    book = textbook_derivation(model)
    data = pm.createData()
    for q, v, _ in states(pm, count=2, seed=23):
        values = dict(zip((*book.q, *book.qd), (*q, *v)))
        M = np.array(book.M.subs(values), dtype=float)
        h = np.array((book.C * sp.Matrix(v) + book.g).subs(values), dtype=float).ravel()
        assert relative(M, symmetric(pin.crba(pm, data, q))) < 1e-10
        assert relative(h, pin.nonLinearEffects(pm, data, q, v)) < 1e-10
