"""Ball (spherical) joints (eomgen.model.quaternion): the generated M, C, g, τ, h, q̈ and the
centroidal quantities against Pinocchio's JointModelSpherical (and JointModelFreeFlyer) with
the same arrays, q (NQ) and v (NV) passed unchanged; integrate and difference against
Pinocchio's; Ṁ − 2C skew by finite differences along integrate.

Pinocchio's models are built by hand from the same list of joints (pin.Model.addJoint with
JointModelSpherical, appendBodyToJoint), not through eomgen's adapter or its expansion of a
ball joint into three virtual joints.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from eomgen.model import Joint, JointType, Link, Transform, build_model, mat3, vec3
from eomgen.model.configuration import difference, integrate, neutral
from support import relative
from support.generated import generated
from support.reference import pinocchio_free_motion, random_inertial, random_rotation
from support.extras import need, skip_backend

pin = need("pinocchio", reason="ball joints are checked against Pinocchio")

#: A chain with two ball joints mid-chain and a branch: (name, type, parent joint index).
CHAIN = (("j0", "revolute", -1), ("ball", "spherical", 0), ("j2", "prismatic", 1),
         ("ball2", "spherical", 1), ("j4", "revolute", 3))
#: A ragdoll on a free flyer: ball hips and shoulders, revolute knees and elbows; names sort
#: in depth-first order (the free flyer's joint order is Pinocchio's URDF reader's).
RAGDOLL = (("a_hip", "spherical", -1), ("b_knee", "revolute", 0),
           ("c_shoulder", "spherical", -1))
KINDS = {"revolute": JointType.REVOLUTE, "prismatic": JointType.PRISMATIC,
         "spherical": JointType.SPHERICAL}
GRAVITY = np.array([0.3, -0.2, -9.81])


def robots(spec, seed, free_flyer=False):
    """The eomgen model (build_model, so ball joints are expanded) and Pinocchio's model built
    by hand from ``spec``: random joint placements and axes, every link with mass."""
    from eomgen.model.floating import add_free_flyer
    rng = np.random.default_rng(seed)
    root_inertia = random_inertial(rng)
    links, joints = [Link("trunk", root_inertia)], []
    pm = pin.Model()
    parent_id = 0
    if free_flyer:
        parent_id = pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
        pm.appendBodyToJoint(parent_id, pin_inertia(root_inertia), pin.SE3.Identity())
    ids = []
    for k, (name, kind, parent) in enumerate(spec):
        R, p = random_rotation(rng), rng.uniform(-0.5, 0.5, 3)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        inertial = random_inertial(rng)
        links.append(Link(f"link_{name}", inertial))
        joints.append(Joint(name, KINDS[kind], "trunk" if parent < 0 else f"link_{spec[parent][0]}",
                            f"link_{name}", Transform(mat3(R.tolist()), vec3(p.tolist())),
                            vec3(axis.tolist())))
        model = {"revolute": pin.JointModelRevoluteUnaligned, "spherical": pin.JointModelSpherical,
                 "prismatic": pin.JointModelPrismaticUnaligned}[kind]
        jid = pm.addJoint(parent_id if parent < 0 else ids[parent],
                          model() if kind == "spherical" else model(axis), pin.SE3(R, p), name)
        pm.appendBodyToJoint(jid, pin_inertia(inertial), pin.SE3.Identity())
        pm.addBodyFrame(f"link_{name}", jid, pin.SE3.Identity(), 0)
        ids.append(jid)
    model = build_model("<test>", "ragdoll" if free_flyer else "ball_chain", links, joints,
                        gravity=GRAVITY.tolist())
    pm.gravity = pin.Motion(GRAVITY, np.zeros(3))
    return (add_free_flyer(model) if free_flyer else model), pm


def pin_inertia(inertial):
    return pin.Inertia(float(inertial.mass), np.array([float(x) for x in inertial.com]),
                       np.array([[float(x) for x in row] for row in inertial.inertia]))


def states(pm, count=2, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


DYNAMICS = ("M", "C", "g", "tau", "h", "qdd_aba", "forward_dynamics")
CENTROIDAL = ("c_G", "J_G", "A_G", "dAGv")


FRAMES = ("p_f", "J_f", "dJqd_f", "Jb_f", "dJbqd_f")
SPECS = {"chain": (CHAIN, 1, False), "ragdoll": (RAGDOLL, 2, True)}


@pytest.fixture(scope="module", params=[pytest.param("chain", marks=pytest.mark.slow),
                                        "ragdoll"])
def case(request, tmp_path_factory):
    """The chain (fixed base, two ball joints, slow) or the ragdoll (free flyer, ball hips and
    shoulder below it) in a NumPy module, and Pinocchio's model."""
    model, pm = robots(*SPECS[request.param])
    calls, modules = generated(model, DYNAMICS + CENTROIDAL + FRAMES + ("Y", "pi"),
                               tmp_path_factory.mktemp(request.param), backends=("numpy",))
    return model, pm, calls["numpy"], modules["numpy"]


@pytest.fixture(scope="module")
def ragdoll_base(tmp_path_factory):
    """The ragdoll's base regressor (the numeric route samples the regressor: slow)."""
    model, pm = robots(*SPECS["ragdoll"])
    calls, _ = generated(model, ("Y_base", "beta"), tmp_path_factory.mktemp("ragdoll_base"),
                         backends=("numpy",))
    return model, pm, calls["numpy"]


@pytest.fixture(scope="module")
def chain_backends(tmp_path_factory):
    """A shorter chain (a ball joint between two revolute joints) in every backend."""
    model, pm = robots(CHAIN[:2] + (("j2", "revolute", 1),), seed=1)
    calls, modules = generated(model, DYNAMICS, tmp_path_factory.mktemp("ball_backends"))
    return model, pm, calls, modules


def expected(pm, q, v, a):
    """Pinocchio's values of the generated functions at ``(q, v, a)``."""
    data = pm.createData()
    M = pin.crba(pm, data, q)
    tau = pin.rnea(pm, data, q, v, a).copy()
    return [
        ("mass_matrix", (q,), np.triu(M) + np.triu(M, 1).T),
        ("coriolis_matrix", (q, v), pin.computeCoriolisMatrix(pm, data, q, v).copy()),
        ("gravity_vector", (q,), pin.computeGeneralizedGravity(pm, data, q).copy()),
        ("inverse_dynamics", (q, v, a), tau),
        ("nonlinear_effects", (q, v), pin.nonLinearEffects(pm, data, q, v).copy()),
        ("forward_dynamics_aba", (q, v, tau), pin.aba(pm, data, q, v, tau).copy()),
        ("forward_dynamics", (q, v, tau), a),
        ("center_of_mass", (q,), pin.centerOfMass(pm, data, q).copy()),
        ("center_of_mass_jacobian", (q,), pin.jacobianCenterOfMass(pm, data, q).copy()),
        ("centroidal_momentum_matrix", (q,), pin.computeCentroidalMap(pm, data, q).copy()),
        ("centroidal_momentum_bias", (q, v),
         pin.computeCentroidalMapTimeVariation(pm, data, q, v) @ v)]


def test_layout_is_pinocchios(case):
    model, pm, _, namespace = case
    assert (model.nq, model.dof) == (pm.nq, pm.nv)
    assert (namespace["NQ"], namespace["NV"]) == (pm.nq, pm.nv)
    assert tuple(namespace["CONFIGURATION_NAMES"]) == model.configuration_names
    balls = [j for j in model.quaternion_joints if j.kind == "spherical"]
    for joint in balls:
        jid = pm.getJointId(joint.name)
        assert (joint.q_index, joint.v_index) == (pm.joints[jid].idx_q, pm.joints[jid].idx_v)
        k = joint.v_index
        assert model.joint_names[k:k + 3] == tuple(f"{joint.name}_{a}" for a in ("wx", "wy", "wz"))
        assert model.configuration_names[joint.q_index:joint.q_index + 4] == tuple(
            f"{joint.name}_{a}" for a in ("qx", "qy", "qz", "qw"))
    assert len(balls) == 2
    assert model.free_flyer == (pm.names[1] == "root_joint")


def test_dynamics_equal_pinocchio(case):
    """M, C, g, τ, h, both forward dynamics, the centroidal quantities, and the leaf links'
    positions, world-aligned and body Jacobians and both J̇ v (Pinocchio's classical and
    spatial frame accelerations at v̇ = 0)."""
    _, pm, call, namespace = case
    data = pm.createData()
    for q, v, a in states(pm, seed=5):
        for function, inputs, value in expected(pm, q, v, a):
            got = call(function, *inputs).ravel()[:value.size].reshape(value.shape)
            assert relative(got, value) < 1e-10, function
        pin.forwardKinematics(pm, data, q, v, np.zeros(pm.nv))
        pin.computeJointJacobians(pm, data, q)
        pin.updateFramePlacements(pm, data)
        p_f, J_f, dJ = call("frame_positions", q), call("frame_jacobians", q), \
            call("frame_jacobians_dot_qd", q, v)
        Jb_f, dJb = call("frame_body_jacobians", q), call("frame_body_jacobians_dot_qd", q, v)
        world = pin.LOCAL_WORLD_ALIGNED
        for k, name in enumerate(namespace["FRAME_NAMES"]):
            fid = pm.getFrameId(name)
            assert relative(p_f[k], data.oMf[fid].translation) < 1e-10
            assert relative(J_f[6 * k:6 * k + 6], pin.getFrameJacobian(pm, data, fid, world)) \
                < 1e-10
            assert relative(dJ[6 * k:6 * k + 6], pin.getFrameClassicalAcceleration(
                pm, data, fid, world).vector) < 1e-10
            assert relative(Jb_f[6 * k:6 * k + 6],
                            pin.getFrameJacobian(pm, data, fid, pin.LOCAL)) < 1e-10
            assert relative(dJb[6 * k:6 * k + 6], pin.getFrameAcceleration(
                pm, data, fid, pin.LOCAL).vector) < 1e-10


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["numpy", "fast", "casadi", "jax", "torch"])
def test_every_backend_equals_pinocchio(chain_backends, backend):
    """M, C, g, τ, h and both forward dynamics of a ball joint in every code backend."""
    _, pm, calls, _ = chain_backends
    if backend not in calls:
        skip_backend(backend)
    call = calls[backend]
    for q, v, a in states(pm, count=1, seed=3):
        for function, inputs, value in expected(pm, q, v, a)[:7]:
            if backend == "casadi" and function == "forward_dynamics":
                continue  # CasADi's module has no Cholesky forward_dynamics
            got = call(function, *inputs).ravel()[:value.size].reshape(value.shape)
            assert relative(got, value) < 1e-10, function


def test_regressor_equals_pinocchio(case):
    """Y against computeJointTorqueRegressor: the columns of each Pinocchio joint's body are
    those of the last virtual joint of its chain (a quaternion joint) or of the joint itself;
    the virtual joints' massless bodies add columns of their own, which multiply zero
    parameters; Y π = τ (rnea)."""
    model, pm, call, _ = case
    columns = []
    for jid in range(1, pm.njoints):
        last = pm.joints[jid].idx_v + pm.joints[jid].nv - 1
        columns += range(10 * last, 10 * last + 10)
    pi = call("inertial_parameters").ravel()
    others = np.setdiff1d(np.arange(len(pi)), columns)
    assert len(others) == 10 * (model.dof - pm.njoints + 1) and not pi[others].any()
    data = pm.createData()
    for q, v, a in states(pm, seed=21):
        Y = call("regressor", q, v, a)
        assert relative(Y[:, columns], pin.computeJointTorqueRegressor(pm, data, q, v, a)) \
            < 1e-10
        assert relative(Y @ pi, pin.rnea(pm, data, q, v, a)) < 1e-10


@pytest.mark.slow
def test_base_regressor_equals_pinocchios_rank(ragdoll_base):
    """Y_base β = τ (rnea), and Y_base has as many columns as Pinocchio's regressor has rank
    over random states (the virtual links' columns take no base parameter)."""
    _, pm, call = ragdoll_base
    data = pm.createData()
    beta = call("base_parameters").ravel()
    stacked = []
    for q, v, a in states(pm, count=8, seed=23):
        Y_base = call("base_regressor", q, v, a)
        assert relative(Y_base @ beta, pin.rnea(pm, data, q, v, a)) < 1e-10
        stacked.append(pin.computeJointTorqueRegressor(pm, data, q, v, a).copy())
    s = np.linalg.svd(np.vstack(stacked), compute_uv=False)
    assert len(beta) == Y_base.shape[1] == int(np.sum(s > 1e-9 * s[0]))


def test_coriolis_is_skew_compatible(case):
    """Ṁ − 2C skew-symmetric, Ṁ by a central difference along integrate(q, v, ±h)."""
    model, pm, call, _ = case
    for q, v, _ in states(pm, count=1, seed=7):
        h = 1e-6
        Mdot = (call("mass_matrix", integrate(q, v, h, model))
                - call("mass_matrix", integrate(q, v, -h, model))) / (2 * h)
        N = Mdot - 2 * call("coriolis_matrix", q, v)
        assert np.abs(N + N.T).max() < 1e-6 * max(1.0, np.abs(Mdot).max())
        assert np.abs(Mdot).max() > 1e-3  # the check is not vacuous


def test_non_unit_quaternions_are_normalised(case):
    model, pm, call, _ = case
    q, v, a = next(states(pm, seed=9))
    scaled = q.copy()
    for joint in model.quaternion_joints:
        scaled[joint.quaternion:joint.quaternion + 4] *= 2.5
    assert relative(call("inverse_dynamics", scaled, v, a), call("inverse_dynamics", q, v, a)) \
        < 1e-12
    assert relative(call("coriolis_matrix", scaled, v), call("coriolis_matrix", q, v)) < 1e-12


@pytest.mark.parametrize("name", SPECS)
def test_integrate_and_difference_equal_pinocchio(name):
    rng = np.random.default_rng(11)
    model, pm = robots(*SPECS[name])
    assert np.array_equal(neutral(model), pin.neutral(pm))
    for q, v, _ in states(pm, count=2, seed=13):
        dt = rng.uniform(0.1, 2.0)
        q1, reference = integrate(q, v, dt, model), pin.integrate(pm, q, v * dt)
        for joint in model.quaternion_joints:  # q and −q are the same rotation
            k = joint.quaternion
            if q1[k:k + 4] @ reference[k:k + 4] < 0:
                q1[k:k + 4] *= -1
        assert relative(q1, reference) < 1e-12
        assert relative(difference(q, q1, model), pin.difference(pm, q, reference)) < 1e-10


def test_yaml_spherical_joint_through_the_pinocchio_adapter(tmp_path):
    """``type: spherical`` in eomgen's YAML format: the model's Pinocchio adapter
    (eomgen.numeric.pinocchio.to_pinocchio) has a JointModelSpherical with the same layout,
    and the generated M and τ take its arrays unchanged."""
    import eomgen
    from eomgen.numeric.pinocchio import to_pinocchio
    text = """name: pendulum
gravity: [0, 0, -9.81]
links:
  - {name: base}
  - {name: upper, mass: 1.5, com: [0, 0, -0.4], inertia: {ixx: 0.05, iyy: 0.06, izz: 0.01}}
  - {name: lower, mass: 0.7, com: [0.1, 0, -0.3], inertia: {ixx: 0.02, iyy: 0.03, izz: 0.01}}
joints:
  - {name: shoulder, type: spherical, parent: base, child: upper,
     origin: {xyz: [0, 0.1, 0], rpy: [0.2, 0, 0]}}
  - {name: elbow, type: revolute, parent: upper, child: lower, origin: {xyz: [0, 0, -0.8]},
     axis: [0, 1, 0]}
"""
    path = tmp_path / "pendulum.yaml"
    path.write_text(text, encoding="utf-8")
    model = eomgen.load(path)
    assert model.ball_joints == ("shoulder",) and (model.nq, model.dof) == (5, 4)
    pm = to_pinocchio(model)
    assert pm.identity and pm.model.names[1] == "shoulder" and pm.model.nq == 5
    calls, _ = generated(model, ("M", "tau"), tmp_path, backends=("numpy",))
    call = calls["numpy"]
    for q, v, a in states(pm.model, seed=17):
        assert relative(call("inverse_dynamics", q, v, a),
                        pin.rnea(pm.model, pm.data, q, v, a)) < 1e-10
        assert relative(call("mass_matrix", q), pm.crba(q)) < 1e-10


@pytest.mark.parametrize("text, message", [
    ("axis: [0, 0, 1]", r"joints\[0\] 'shoulder' axis: a spherical joint has no axis"),
    ("actuator: {armature: 0.1, stiffness: 20}",
     r"ball joint 'shoulder': a ball joint's stiffness is not modelled yet"),
])
def test_yaml_spherical_joint_errors(tmp_path, text, message):
    import eomgen
    from eomgen.errors import DescriptionError
    path = tmp_path / "bad.yaml"
    path.write_text("name: bad\nlinks:\n  - {name: base}\n  - {name: upper, mass: 1}\n"
                    "joints:\n  - {name: shoulder, type: spherical, parent: base, "
                    f"child: upper, {text}}}\n", encoding="utf-8")
    with pytest.raises(DescriptionError, match=message):
        eomgen.load(path)


def test_outputs_not_derived_for_the_chart_are_refused(monkeypatch):
    """The loop rows are derived for ball joints (tests/loops/test_quaternion_loops.py);
    an output the catalogue marked on_charts=False would be refused naming the
    joint."""
    from eomgen import derive
    from eomgen.errors import UnsupportedError
    from eomgen.outputs import BY_SYMBOL
    model, _ = robots(CHAIN[:2], seed=19)
    monkeypatch.setitem(BY_SYMBOL, "Phi_l", replace(BY_SYMBOL["Phi_l"], on_charts=False))
    with pytest.raises(UnsupportedError, match="Phi_l not derived for a ball joint yet"):
        derive(model, outputs=("M", "Phi_l"))


def test_a_broken_ball_chain_is_refused():
    """Locking one of a ball joint's virtual joints leaves no ball joint: refused by name."""
    from eomgen.errors import KinematicTreeError
    model, _ = robots(CHAIN[:2], seed=19)
    joints = tuple(replace(j, type=JointType.FIXED) if j.name == "ball_wy" else j
                   for j in model.joints)
    with pytest.raises(KinematicTreeError, match="ball joint 'ball': its joints ball_wx"):
        replace(model, joints=joints).nq


def test_scene_keeps_or_refuses_a_ball_joint(tmp_path):
    """A scene that locks another joint keeps the ball joint (its quaternion in q); one that
    locks one of its virtual joints is refused in one line naming the entry and the ball joint
    (tests/scenes/test_lock_compound.py locks the ball joint whole)."""
    import eomgen
    from eomgen.errors import SceneError
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene
    path = tmp_path / "pendulum.yaml"
    path.write_text("name: pendulum\nlinks:\n  - {name: base}\n  - {name: upper, mass: 1}\n"
                    "  - {name: lower, mass: 1}\njoints:\n"
                    "  - {name: shoulder, type: spherical, parent: base, child: upper}\n"
                    "  - {name: elbow, type: revolute, parent: upper, child: lower}\n",
                    encoding="utf-8")
    model = eomgen.load(path)
    kept, _ = apply_scene(model, load_scene("s.yaml", text="version: 1\nlocked: {elbow: 0}\n"))
    assert kept.configuration_names == ("shoulder_qx", "shoulder_qy", "shoulder_qz",
                                        "shoulder_qw")
    with pytest.raises(SceneError, match="locked 'shoulder_wy': a virtual joint of ball joint "
                       "'shoulder': lock 'shoulder' at its configuration"):
        apply_scene(model, load_scene("s.yaml", text="version: 1\nlocked: {shoulder_wy: 0}\n"))


def test_verify_checks_ball_joints():
    """eomgen verify's reference Newton–Euler takes the ball joint's quaternion (NQ) and
    angular velocity (NV): every check passes (tests/analysis/test_numeric_quaternion.py checks
    that reference against Pinocchio)."""
    from eomgen import derive
    from eomgen.verify import verify
    model, _ = robots(CHAIN[:2], seed=19)
    report = verify(derive(model, outputs=("M", "C", "g")), samples=3)
    assert report.passed, report.format()


def test_simulate_a_ball_joint_keeps_energy_and_follows_pinocchio():
    """eomgen.analysis.simulate integrates a ball joint's quaternion (q̇ from
    configuration_rate): RK4 keeps the energy, and the final state is Pinocchio's (aba and
    integrate, integrated by SciPy's DOP853)."""
    need("scipy", reason="the reference trajectory is SciPy's DOP853")
    from eomgen.analysis.simulate import RK4, System, energies, simulate
    model, pm = robots(CHAIN[:2], seed=29)
    system = System(model)
    q0 = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
    v0 = np.array([0.5, 1.0, -2.0, 0.7])
    trajectory, _ = simulate(system, RK4(dt=1e-3), q0, v0, duration=0.4, points=41)
    K, P = energies(system, trajectory)
    E = K + P
    assert np.abs(E - E[0]).max() < 1e-8 * max(1.0, np.abs(K).max())
    assert np.abs(K - K[0]).max() > 1e-2 * np.abs(K).max()  # energy moves between K and P
    q, v = pinocchio_free_motion(pm, q0, v0, 0.4)
    assert np.abs(difference(q, trajectory.q[-1], model)).max() < 1e-8
    assert relative(trajectory.qd[-1], v) < 1e-8


def test_pinocchio_adapter_maps_quaternion_joints_in_any_joint_order():
    """eomgen.numeric.pinocchio.to_pinocchio: for the ragdoll (free flyer, ball joints) the
    hand-built model's M and τ with the arrays unchanged; for the chain with its joints
    listed out of depth-first order, the same τ and M as in depth-first order once q and v are
    matched by name (the adapter's perm and qperm)."""
    from eomgen.numeric.pinocchio import to_pinocchio
    model, pm = robots(*SPECS["ragdoll"])
    adapted = to_pinocchio(model)
    assert adapted.identity and list(adapted.model.names) == list(pm.names)
    data = pm.createData()
    for q, v, a in states(pm, seed=31):
        assert relative(adapted.rnea(q, v, a), pin.rnea(pm, data, q, v, a)) < 1e-12
        assert relative(adapted.crba(q), pin.crba(pm, data, q)) < 1e-12
    ordered, pm = robots(CHAIN, seed=1)
    joints = {j.name: j for j in ordered.joints}
    shuffled = replace(ordered, joints=tuple(joints[n] for n in (
        "j4", "ball2_wx", "ball2_wy", "ball2_wz", "j0", "j2", "ball_wx", "ball_wy", "ball_wz")))
    assert shuffled.joint_names[0] == "j4"
    adapted = to_pinocchio(shuffled)
    assert not adapted.identity
    q_names, v_names = shuffled.configuration_names, shuffled.joint_names
    q_map = [ordered.configuration_names.index(n) for n in q_names]
    v_map = [ordered.joint_names.index(n) for n in v_names]
    for q, v, a in states(pm, seed=33):
        tau = pin.rnea(pm, data := pm.createData(), q, v, a)
        M = pin.crba(pm, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        assert relative(adapted.rnea(q[q_map], v[v_map], a[v_map]), tau[v_map]) < 1e-12
        assert relative(adapted.crba(q[q_map]), M[np.ix_(v_map, v_map)]) < 1e-12
