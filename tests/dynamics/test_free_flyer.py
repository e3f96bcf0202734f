"""The quaternion free flyer (eomgen.model.floating): every code backend's M, C, g, tau, h and q̈
against Pinocchio's JointModelFreeFlyer with the same arrays, q (NQ) and v (NV) passed
unchanged; integrate and difference against Pinocchio's; Ṁ − 2C skew by finite differences.

The robot is a random tree (revolute and prismatic joints with general axes, fixed links) whose
links all carry mass (M positive definite); Pinocchio reads it from the URDF text eomgen writes of it, with its own
reader and its own free flyer.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from eomgen.model.floating import add_free_flyer, difference, integrate, neutral
from support import relative
from support.generated import generated
from support.reference import massive_tree as floating_tree, pinocchio_free_motion, to_urdf
from support.extras import need, skip_backend

pin = need("pinocchio", reason="the free flyer is checked against Pinocchio")

FUNCTIONS = ("M", "C", "g", "tau", "h", "qdd_aba", "forward_dynamics")




@pytest.fixture(scope="module")
def case(tmp_path_factory):
    fixed = floating_tree(5, 3)
    model = add_free_flyer(fixed)
    folder = tmp_path_factory.mktemp("free_flyer")
    urdf = folder / "tree.urdf"
    urdf.write_text(to_urdf(fixed), encoding="utf-8")
    pm = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    pm.gravity = pin.Motion(np.array([float(x) for x in fixed.gravity]), np.zeros(3))
    calls, modules = generated(model, FUNCTIONS, folder)
    return model, pm, calls, modules


def states(pm, count=3, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


def test_layout_is_pinocchios(case):
    model, pm, _, modules = case
    assert (model.nq, model.dof) == (pm.nq, pm.nv)
    names = [n for n in pm.names[2:]]
    for namespace in modules.values():
        assert namespace["NQ"] == pm.nq and namespace["NV"] == pm.nv
        assert list(namespace["JOINT_NAMES"][6:]) == names
        if "CONFIGURATION_NAMES" in namespace:
            assert namespace["CONFIGURATION_NAMES"][3:7] == ("base_qx", "base_qy", "base_qz",
                                                             "base_qw")


@pytest.mark.parametrize("backend", ["numpy", "fast", "casadi", "jax", "torch"])
def test_dynamics_equal_pinocchio(case, backend):
    model, pm, calls, _ = case
    if backend not in calls:
        skip_backend(backend)
    call, data = calls[backend], pm.createData()
    for q, v, a in states(pm):
        M = pin.crba(pm, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        tau = pin.rnea(pm, data, q, v, a)
        expected = {
            "M": M, "C": pin.computeCoriolisMatrix(pm, data, q, v).copy(),
            "g": pin.computeGeneralizedGravity(pm, data, q).copy(),
            "tau": tau, "h": pin.nonLinearEffects(pm, data, q, v).copy()}
        got = {"M": call("mass_matrix", q), "C": call("coriolis_matrix", q, v), "g": call("gravity_vector", q),
               "tau": call("inverse_dynamics", q, v, a), "h": call("nonlinear_effects", q, v)}
        for name, value in expected.items():
            assert relative(got[name].reshape(value.shape), value) < 1e-10, name
        assert relative(call("forward_dynamics_aba", q, v, tau).ravel(), a) < 1e-10
        if backend != "casadi":
            qdd = call("forward_dynamics", q, v, tau)
            assert relative(np.asarray(qdd).ravel()[:len(a)], a) < 1e-9


def test_non_unit_quaternion_is_normalised(case):
    _, pm, calls, _ = case
    call = calls["numpy"]
    q, v, a = next(states(pm, seed=3))
    scaled = q.copy()
    scaled[3:7] *= 2.5
    assert relative(call("inverse_dynamics", scaled, v, a), call("inverse_dynamics", q, v, a)) < 1e-12
    assert relative(call("mass_matrix", scaled), call("mass_matrix", q)) < 1e-12


def test_coriolis_is_skew_compatible(case):
    """Ṁ − 2C skew-symmetric, Ṁ by a central difference along integrate(q, v, ±h)."""
    _, pm, calls, _ = case
    call = calls["numpy"]
    for q, v, _ in states(pm, count=2, seed=7):
        h = 1e-6
        Mdot = (call("mass_matrix", integrate(q, v, h)) - call("mass_matrix", integrate(q, v, -h))) / (2 * h)
        N = Mdot - 2 * call("coriolis_matrix", q, v)
        assert np.abs(N + N.T).max() < 1e-6 * max(1.0, np.abs(Mdot).max())


def test_integrate_and_difference_equal_pinocchio(case):
    _, pm, _, _ = case
    rng = np.random.default_rng(11)
    for q, v, _ in states(pm, count=3, seed=13):
        dt = rng.uniform(0.1, 2.0)
        q1 = integrate(q, v, dt)
        expected = pin.integrate(pm, q, v * dt)
        same_sign = np.sign(expected[6]) * np.sign(q1[6]) if q1[6] else 1.0
        assert relative(q1[:3], expected[:3]) < 1e-12
        assert relative(q1[3:7] * same_sign, expected[3:7]) < 1e-12
        assert relative(q1[7:], expected[7:]) < 1e-12
        assert relative(difference(q, q1), pin.difference(pm, q, expected)) < 1e-10
    assert np.array_equal(neutral(pm.nq), pin.neutral(pm))


SOLO = "solo_description/robots/solo12.urdf"
TALOS = "talos_data/robots/talos_reduced.urdf"


def erd_path(relative_path):
    from support import erd_robots_dir
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    return robots / relative_path


GO1 = "go1_description/urdf/go1.urdf"


@pytest.mark.parametrize("robot, tips", [
    pytest.param(SOLO, None, id="solo12"),
    pytest.param(GO1, None, id="go1", marks=pytest.mark.slow),
    pytest.param(TALOS, ("leg_left_6_link", "leg_right_6_link"), id="talos_legs",
                 marks=pytest.mark.slow)])
def test_scene_quaternion_base_equals_pinocchio(robot, tips, tmp_path):
    """``floating_base: quaternion`` in a scene: the NumPy module of solo12, of Go1 (its rotors
    written as fixed links) and of Talos's legs (the rest locked at 0) takes Pinocchio's arrays
    unchanged: M, C, g, τ, h, the ABA and the centroidal quantities."""
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene
    from support import load_quietly
    path = erd_path(robot)
    text = "version: 1\nfloating_base: quaternion\n" + (
        f"tips: [{', '.join(tips)}]\n" if tips else "")
    model, report = apply_scene(load_quietly(path), load_scene("legs.yaml", text=text))
    assert model.free_flyer and any("free flyer" in note for note in report.notes)
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    locked = [pm.getJointId(n) for n in pm.names[2:] if n not in model.joint_names]
    if locked:
        pm = pin.buildReducedModel(pm, locked, pin.neutral(pm))
    assert list(model.joint_names[6:]) == list(pm.names[2:])
    calls, _ = generated(model, ("M", "C", "g", "tau", "h", "qdd_aba", "c_G", "J_G", "A_G",
                                 "dAGv"), tmp_path, backends=("numpy",))
    call, data = calls["numpy"], pm.createData()
    for q, v, a in states(pm, count=2, seed=17):
        M = pin.crba(pm, data, q)
        tau = pin.rnea(pm, data, q, v, a).copy()
        expected = [
            ("mass_matrix", (q,), np.triu(M) + np.triu(M, 1).T),
            ("coriolis_matrix", (q, v), pin.computeCoriolisMatrix(pm, data, q, v).copy()),
            ("gravity_vector", (q,), pin.computeGeneralizedGravity(pm, data, q).copy()),
            ("inverse_dynamics", (q, v, a), tau),
            ("nonlinear_effects", (q, v), pin.nonLinearEffects(pm, data, q, v).copy()),
            ("forward_dynamics_aba", (q, v, tau), a),
            ("center_of_mass", (q,), pin.centerOfMass(pm, data, q).copy()),
            ("center_of_mass_jacobian", (q,), pin.jacobianCenterOfMass(pm, data, q).copy()),
            ("centroidal_momentum_matrix", (q,), pin.computeCentroidalMap(pm, data, q).copy()),
            ("centroidal_momentum_bias", (q, v),
             pin.computeCentroidalMapTimeVariation(pm, data, q, v) @ v)]
        for function, inputs, value in expected:
            got = call(function, *inputs).reshape(value.shape)
            assert relative(got, value) < 1e-10, function


def test_outputs_not_derived_for_the_chart_are_refused(monkeypatch):
    """An output the catalogue marks on_charts=False (the second derivatives today) is
    refused in one line; the loop rows are derived on the chart (without loops they ask for
    some)."""
    from eomgen import derive
    from eomgen.errors import GenerationError, UnsupportedError
    from eomgen.outputs import BY_SYMBOL
    model = add_free_flyer(floating_tree(5, 2))
    with pytest.raises(GenerationError, match="need loops"):
        derive(model, outputs=("M", "Phi_l"))
    monkeypatch.setitem(BY_SYMBOL, "Phi_l", replace(BY_SYMBOL["Phi_l"], on_charts=False))
    with pytest.raises(UnsupportedError,
                       match="Phi_l not derived for a quaternion free flyer yet"):
        derive(model, outputs=("M", "Phi_l"))


@pytest.fixture(scope="module")
def contact_case(tmp_path_factory):
    """The random tree on a point contact (a leaf link) and a surface contact (another link),
    its frames' kinematics and contact outputs in a NumPy module, and Pinocchio's model."""
    from eomgen.model import Contact
    fixed = floating_tree(5, 3)
    parents = {j.parent for j in fixed.joints}
    leaves = [l.name for l in fixed.links if l.name not in parents]
    contacts = (Contact(leaves[0], "point", name="foot"),
                Contact(leaves[-1], "surface", name="hand"))
    model = replace(add_free_flyer(fixed), contacts=contacts)
    folder = tmp_path_factory.mktemp("free_flyer_contacts")
    (folder / "tree.urdf").write_text(to_urdf(fixed), encoding="utf-8")
    pm = pin.buildModelFromUrdf(str(folder / "tree.urdf"), pin.JointModelFreeFlyer())
    pm.gravity = pin.Motion(np.array([float(x) for x in fixed.gravity]), np.zeros(3))
    outputs = ("M", "h", "J_f", "Jb_f", "dJqd_f", "dJbqd_f", "p_f", "J_c", "dJqd_c",
               "tau", "tau_c", "constrained_forward_dynamics", "c_G", "J_G", "A_G", "dAGv",
               "I_G")
    calls, modules = generated(model, outputs, folder, backends=("numpy",))
    return model, pm, calls["numpy"], modules["numpy"]


def test_frames_equal_pinocchio(contact_case):
    """Frame origins, world-aligned and body Jacobians (NV wide) and both J̇ v against
    Pinocchio's frame Jacobians and accelerations at v̇ = 0."""
    _, pm, call, module = contact_case
    data = pm.createData()
    for q, v, _ in states(pm, count=2, seed=23):
        pin.forwardKinematics(pm, data, q, v, np.zeros(pm.nv))
        pin.computeJointJacobians(pm, data, q)
        pin.updateFramePlacements(pm, data)
        p_f, J_f, Jb_f = call("frame_positions", q), call("frame_jacobians", q), \
            call("frame_body_jacobians", q)
        dJ, dJb = call("frame_jacobians_dot_qd", q, v), call("frame_body_jacobians_dot_qd", q, v)
        assert J_f.shape[1] == pm.nv
        for k, name in enumerate(module["FRAME_NAMES"]):
            fid = pm.getFrameId(name)
            world = pin.LOCAL_WORLD_ALIGNED
            assert relative(p_f[k], data.oMf[fid].translation) < 1e-10
            assert relative(J_f[6 * k:6 * k + 6],
                            pin.getFrameJacobian(pm, data, fid, world)) < 1e-10
            assert relative(Jb_f[6 * k:6 * k + 6],
                            pin.getFrameJacobian(pm, data, fid, pin.LOCAL)) < 1e-10
            assert relative(dJ[6 * k:6 * k + 6], pin.getFrameClassicalAcceleration(
                pm, data, fid, world).vector) < 1e-10
            assert relative(dJb[6 * k:6 * k + 6], pin.getFrameAcceleration(
                pm, data, fid, pin.LOCAL).vector) < 1e-10


def test_constrained_dynamics_hold_the_contacts(contact_case):
    """constrained_forward_dynamics solves M v̇ + h = τ + J_cᵀ F_c, J_c v̇ + J̇_c v = 0 with
    Pinocchio's M and h; contact_inverse_dynamics gives τ back."""
    _, pm, call, module = contact_case
    data = pm.createData()
    for q, v, tau in states(pm, count=2, seed=29):
        qdd, F = module["constrained_forward_dynamics"](q, v, tau)
        M = pin.crba(pm, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        J, bias = call("contact_jacobian", q), call("contact_bias", q, v)
        assert J.shape == (9, pm.nv)
        assert relative(M @ qdd + pin.nonLinearEffects(pm, data, q, v), tau + J.T @ F) < 1e-9
        assert np.abs(J @ qdd + bias).max() < 1e-9 * max(1.0, np.abs(bias).max())
        assert relative(call("contact_inverse_dynamics", q, v, qdd, F), tau) < 1e-9


def test_centroidal_quantities_equal_pinocchio(contact_case):
    """Centre of mass, its Jacobian, A_G, Ȧ_G v and the centroidal composite inertia against
    centerOfMass, jacobianCenterOfMass, computeCentroidalMap, computeCentroidalMapTimeVariation
    and ccrba's Ig; and the centroidal equation ḣ_G = [m g; 0] in free fall (Pinocchio's aba)."""
    _, pm, call, _ = contact_case
    data = pm.createData()
    mass = sum(inertia.mass for inertia in pm.inertias)
    for q, v, _ in states(pm, count=2, seed=31):
        assert relative(call("center_of_mass", q), pin.centerOfMass(pm, data, q)) < 1e-10
        assert relative(call("center_of_mass_jacobian", q),
                        pin.jacobianCenterOfMass(pm, data, q)) < 1e-10
        A_G = call("centroidal_momentum_matrix", q)
        assert relative(A_G, pin.computeCentroidalMap(pm, data, q)) < 1e-10
        dA = pin.computeCentroidalMapTimeVariation(pm, data, q, v)
        bias = call("centroidal_momentum_bias", q, v)
        assert relative(bias, dA @ v) < 1e-10
        pin.ccrba(pm, data, q, v)
        assert relative(call("centroidal_composite_inertia", q), data.Ig.matrix()) < 1e-10
        falling = pin.aba(pm, data, q, v, np.zeros(pm.nv))
        rate = A_G @ falling + bias
        assert relative(rate, np.concatenate([mass * pm.gravity.linear, np.zeros(3)])) < 1e-9


def test_tumbling_through_pitch_90_degrees_keeps_energy(tmp_path):
    """A free-flying tree spun about its pitch axis passes pitch ±90° (where the Euler chart is
    singular) with the quaternion base: RK4 of eomgen.analysis.simulate keeps the energy, and
    its final state is Pinocchio's (aba and integrate, integrated by SciPy's DOP853)."""
    from eomgen.analysis.simulate import RK4, System, energies, simulate
    fixed = floating_tree(7, 2)
    model = add_free_flyer(fixed)
    system = System(model)
    pitch = np.radians(80)  # about the root's y axis, 10° short of the Euler chart's singularity
    q0 = np.array([0.0, 0.0, 1.0, 0.0, np.sin(pitch / 2), 0.0, np.cos(pitch / 2), 0.3, -0.2])
    v0 = np.array([0.1, 0.0, 0.2, 0.05, 2.0, -0.05, 0.5, 0.0])
    trajectory, _ = simulate(system, RK4(dt=1e-3), q0, v0, duration=0.5, points=51)
    assert np.all(np.isfinite(trajectory.q))
    R20 = [2 * (x * z - y * w) / (x * x + y * y + z * z + w * w)
           for x, y, z, w in trajectory.q[:, 3:7]]  # -sin(pitch) of R = Rz Ry Rx
    assert max(abs(r) for r in R20) > 0.9998  # pitch came within about 1° of ±90°
    K, P = energies(system, trajectory)
    E = K + P
    assert np.abs(E - E[0]).max() < 1e-8 * max(1.0, np.abs(K).max())
    (tmp_path / "tree.urdf").write_text(to_urdf(fixed), encoding="utf-8")
    pm = pin.buildModelFromUrdf(str(tmp_path / "tree.urdf"), pin.JointModelFreeFlyer())
    pm.gravity = pin.Motion(np.array([float(x) for x in fixed.gravity]), np.zeros(3))
    q, v = pinocchio_free_motion(pm, q0, v0, 0.5)
    final = trajectory.q[-1].copy()
    final[3:7] /= np.linalg.norm(final[3:7])
    assert np.abs(difference(q, final)).max() < 1e-8 * max(1.0, np.abs(q[:3]).max())
    assert relative(trajectory.qd[-1], v) < 1e-8


def test_simulate_takes_a_quaternion_q0_of_nq_values(tmp_path):
    """``eomgen simulate`` of a quaternion scene names the NQ configuration entries when --q0
    has another length, in one line, exit 2, nothing written."""
    from support import run_in_process
    path = erd_path(SOLO)
    scene = tmp_path / "float.yaml"
    scene.write_text("version: 1\nfloating_base: quaternion\n", encoding="utf-8")
    result = run_in_process("simulate", path, "--scene", scene, "--q0", "0,0,0,0,0,0",
                            "-o", tmp_path / "out")
    assert result.returncode == 2 and not (tmp_path / "out").exists()
    line, = result.stderr.strip().splitlines()
    assert "--q0: solo takes 19 values (base_x, base_y, base_z, base_qx" in line


def test_urdf_floating_joint_is_read_as_the_free_flyer(tmp_path):
    """A URDF whose massless root holds the trunk by a ``floating`` joint (with an origin) is
    read as a quaternion free flyer, as Pinocchio's URDF reader reads it: same layout, same
    M, C, g and frame positions with the same arrays."""
    import eomgen
    fixed = floating_tree(5, 2)
    text = to_urdf(fixed).replace(
        f'<link name="{fixed.root}"',
        '<link name="world"/>\n  <joint name="root_joint" type="floating">\n'
        f'    <parent link="world"/>\n    <child link="{fixed.root}"/>\n'
        '    <origin xyz="0.1 -0.2 0.5" rpy="0.3 0.1 -0.2"/>\n  </joint>\n'
        f'  <link name="{fixed.root}"', 1)
    path = tmp_path / "floating.urdf"
    path.write_text(text, encoding="utf-8")
    model = eomgen.load(path)
    assert model.free_flyer and model.nq == model.dof + 1
    pm = pin.buildModelFromUrdf(str(path))  # URDF gravity on both sides: −9.81 along z
    assert pm.names[1] == "root_joint" and (pm.nq, pm.nv) == (model.nq, model.dof)
    calls, _ = generated(model, ("M", "C", "g", "p_f"), tmp_path, backends=("numpy",))
    call, data = calls["numpy"], pm.createData()
    for q, v, _ in states(pm, count=2, seed=37):
        M = pin.crba(pm, data, q)
        assert relative(call("mass_matrix", q), np.triu(M) + np.triu(M, 1).T) < 1e-10
        assert relative(call("coriolis_matrix", q, v),
                        pin.computeCoriolisMatrix(pm, data, q, v)) < 1e-10
        assert relative(call("gravity_vector", q).ravel(),
                        pin.computeGeneralizedGravity(pm, data, q)) < 1e-10
        pin.framesForwardKinematics(pm, data, q)
        leaf = [f.name for f in pm.frames][-1]
        rows = call("frame_positions", q)
        names = [l.name for l in model.links if l.name not in {j.parent for j in model.joints}]
        assert relative(rows[names.index(leaf)], data.oMf[pm.getFrameId(leaf)].translation) \
            < 1e-10
