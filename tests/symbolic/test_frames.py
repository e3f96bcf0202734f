"""Frame kinematics (eomgen.symbolic.frames): pose, Jacobians and J̇ q̇ of named links.

Checked against finite differences of eomgen's own numeric forward kinematics
(:func:`eomgen.numeric.link_poses`, a separate implementation) and against Pinocchio's frame
Jacobians (``LOCAL_WORLD_ALIGNED`` and ``LOCAL``) and frame accelerations.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen import numeric
from eomgen.model import floating
from eomgen.numeric import floating_base
from eomgen.errors import KinematicTreeError
from eomgen.symbolic.frames import derive_frames, frame_site
from support import floating_states, load_quietly
from support.robots import SOLO, FreeFlyerReference
from support.extras import need

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


@pytest.fixture(scope="module")
def solo():
    from support import erd_robots_dir

    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    path = erd_robots_dir() / SOLO
    model = floating.add_floating_base(load_quietly(path))
    return path, model, derive_frames(model, FEET + ("base_link", "FL_UPPER_LEG"))


def _vee(W):
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def test_jacobians_are_finite_differences_of_the_poses(solo):
    _, model, fk = solo
    nm = numeric.numeric_model(model)
    h = 1e-6
    for q, qd in floating_states(18, 2, seed=10):
        out = fk.evaluate(q, qd)
        plus = numeric.link_poses(nm, q + h * qd)
        minus = numeric.link_poses(nm, q - h * qd)
        here = numeric.link_poses(nm, q)
        for name, f in out.items():
            R, p = here[name]
            assert np.allclose(f["p"], p, atol=1e-14) and np.allclose(f["R"], R, atol=1e-14)
            p_dot = (plus[name][1] - minus[name][1]) / (2 * h)
            w = _vee((plus[name][0] - minus[name][0]) / (2 * h) @ R.T)
            assert np.allclose(f["J"] @ qd, np.r_[p_dot, w], atol=1e-8)
            assert np.allclose(f["Jb"] @ qd, np.r_[R.T @ p_dot, R.T @ w], atol=1e-8)
            # J̇ q̇ = d/dt (J q̇) along q(t) = q + t q̇ (q̈ = 0)
            Jdot = (fk.evaluate(q + h * qd)[name]["J"]
                    - fk.evaluate(q - h * qd)[name]["J"]) / (2 * h)
            assert np.allclose(f["dJqd"], Jdot @ qd, atol=1e-7)
            Jbdot = (fk.evaluate(q + h * qd)[name]["Jb"]
                     - fk.evaluate(q - h * qd)[name]["Jb"]) / (2 * h)
            assert np.allclose(f["dJbqd"], Jbdot @ qd, atol=1e-7)


def test_frames_match_pinocchio(solo):
    pin = need("pinocchio", reason="Pinocchio is the reference")
    path, model, fk = solo
    ref = FreeFlyerReference(path, model.joint_names)
    pm, pd, idx = ref.model, ref.data, ref.idx
    for q, qd in floating_states(18, 3, seed=11):
        out = fk.evaluate(q, qd)
        q_pin, v = ref.state(q, qd)
        T = floating_base.velocity_map(q)
        a = floating_base.velocity_map_dot_qd(q, qd)[idx]  # Pinocchio's v̇ when q̈ = 0
        pin.forwardKinematics(pm, pd, q_pin, v, a)
        pin.updateFramePlacements(pm, pd)
        pin.computeJointJacobians(pm, pd, q_pin)
        for name, f in out.items():
            fid = pm.getFrameId(name)
            for frame, key in ((pin.LOCAL_WORLD_ALIGNED, "J"), (pin.LOCAL, "Jb")):
                J = np.empty((6, 18))
                J[:, idx] = pin.getFrameJacobian(pm, pd, fid, frame)
                assert np.allclose(J @ T, f[key], atol=1e-13)
            acc = pin.getFrameClassicalAcceleration(pm, pd, fid, pin.LOCAL_WORLD_ALIGNED)
            assert np.allclose(np.r_[acc.linear, acc.angular], f["dJqd"], atol=1e-12)
            acc = pin.getFrameAcceleration(pm, pd, fid, pin.LOCAL)
            assert np.allclose(np.r_[acc.linear, acc.angular], f["dJbqd"], atol=1e-12)
            placement = pd.oMf[fid]
            assert np.allclose(placement.translation, f["p"], atol=1e-14)
            assert np.allclose(placement.rotation, f["R"], atol=1e-14)


def test_planar_arm_frames_closed_form():
    """The planar 2-link arm's ``tip`` frame (fixed to link2 at its end), symbolic parameters
    kept: p = (l1 c1 + l2 c12, l1 s1 + l2 s12, 0) and the textbook Jacobian, exactly; the
    world-fixed root has a zero Jacobian."""
    import sympy as sp

    arm = eomgen.load(eomgen.example_path("planar_2link"))
    fk = derive_frames(arm)
    assert frame_site(arm, "tip")[0] == "link2"
    q1, q2 = fk.q
    l1, l2 = (sp.Symbol(n, real=True) for n in ("l1", "l2"))
    c1, s1 = sp.cos(q1), sp.sin(q1)
    c12, s12 = sp.cos(q1 + q2), sp.sin(q1 + q2)
    p = fk.program.expand(fk.output("p", "tip"))
    J = fk.program.expand(fk.output("J", "tip"))
    expected_p = sp.Matrix([l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0])
    expected_J = sp.Matrix([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12],
                            [0, 0], [0, 0], [0, 0], [1, 1]])
    assert sp.simplify(sp.expand_trig(p - expected_p)) == sp.zeros(3, 1)
    assert sp.simplify(sp.expand_trig(J - expected_J)) == sp.zeros(6, 2)
    root = fk.evaluate([0.3, -0.7], [1.0, 2.0])[arm.root]
    assert not root["J"].any() and not root["dJqd"].any()


def test_unknown_frame_is_refused():
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    with pytest.raises(KinematicTreeError, match="frame 'hand'"):
        derive_frames(arm, ["hand"])


def test_frame_positions_of_a_tree_whose_first_joint_is_offset():
    """A fixed-base tree whose first moving joint sits away from the root origin: the frame
    origins are world positions (Pinocchio's ``oMf``), not positions from that joint (the
    world-frame kinematics' reference point; a bug until the free flyer's frames showed it)."""
    pin = need("pinocchio", reason="Pinocchio is the reference")
    from support.reference import pin_q_order, random_robot, to_pinocchio
    model = random_robot(np.random.default_rng(5), 3, tree=True)
    assert any(v != 0 for v in model.joints[0].origin.translation)
    leaves = [l.name for l in model.links if l.name not in {j.parent for j in model.joints}]
    frames = derive_frames(model, leaves)
    pm = to_pinocchio(model)
    perm = pin_q_order(model, pm)
    q = np.random.default_rng(1).normal(size=model.dof)
    data = pm.createData()
    pin.forwardKinematics(pm, data, q[perm])
    pin.updateFramePlacements(pm, data)
    for name, values in frames.evaluate(q).items():
        assert np.allclose(values["p"], data.oMf[pm.getFrameId(name)].translation, atol=1e-12)
