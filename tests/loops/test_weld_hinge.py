"""Spatial weld and hinge loops on a closed chain of two arms (3 + 4 revolute joints with
assorted axes, their tips welded): the weld against Pinocchio's ``constraintDynamics`` with a
``CONTACT_6D`` (``LOCAL``) loop (q̈, the loop force and moment, ``λ = −blockdiag(R_a, R_a)
λ_pin``); the hinge as the weld with the last joint cut out: a hinge loop about that joint's
axis on the arms without it gives the same q̈ and, on its rows, the same forces (that joint's
link massless, so that the forces through the cut are that joint's); J̇_l q̇ of both
by finite differences. The frames are placed so that the chain is closed at a chosen q*."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import eomgen
from eomgen.numeric.loops import LoopDynamics
from eomgen.model import HINGE, WELD, Loop, LoopFrame, Transform, mat3, vec3
from eomgen.symbolic.frames import derive_frames
from eomgen.symbolic.loops import plane_axes
from support.extras import need

ARMS = """name: two_arms
gravity: [0, 0, -9.81]
links:
  - {name: base}
  - {name: a1, mass: 1.0, com: [0.1, 0, 0], inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02}}
  - {name: a2, mass: 0.8, com: [0.15, 0, 0], inertia: {ixx: 0.01, iyy: 0.015, izz: 0.02}}
  - {name: a3, mass: 0.5, com: [0.1, 0.02, 0], inertia: {ixx: 0.005, iyy: 0.01, izz: 0.01}}
  - {name: b1, mass: 1.1, com: [0.1, 0, 0], inertia: {ixx: 0.01, iyy: 0.02, izz: 0.025}}
  - {name: b2, mass: 0.7, com: [0.12, 0, 0.01], inertia: {ixx: 0.01, iyy: 0.012, izz: 0.02}}
  - {name: b3, mass: 0.6, com: [0.1, 0, 0], inertia: {ixx: 0.006, iyy: 0.01, izz: 0.01}}
  - {name: b4, mass: 0.3, com: [0.05, 0, 0], inertia: {ixx: 0.002, iyy: 0.003, izz: 0.003}}
joints:
  - {name: ja1, type: revolute, parent: base, child: a1, axis: [0, 0, 1]}
  - {name: ja2, type: revolute, parent: a1, child: a2, origin: {xyz: [0.2, 0, 0.1]}, axis: [0, 1, 0]}
  - {name: ja3, type: revolute, parent: a2, child: a3, origin: {xyz: [0.3, 0, 0]}, axis: [1, 0, 1]}
  - {name: jb1, type: revolute, parent: base, child: b1, origin: {xyz: [0.5, 0.1, 0]}, axis: [0, 0, 1]}
  - {name: jb2, type: revolute, parent: b1, child: b2, origin: {xyz: [0.2, 0, 0.1]}, axis: [1, 1, 0]}
  - {name: jb3, type: revolute, parent: b2, child: b3, origin: {xyz: [0.25, 0, 0]}, axis: [0, 1, 0]}
  - {name: jb4, type: revolute, parent: b3, child: b4, origin: {xyz: [0.2, 0, 0]}, axis: [0, 0.6, 0.8]}
"""
Q_STAR = np.array([0.3, -0.4, 0.7, 2.2, 0.5, -0.8, 0.9])
K = np.array([0.0, 0.6, 0.8])  # jb4's axis, in b4's (= b3's at q = 0) frame


def _transform(R, p) -> Transform:
    return Transform(mat3(R.tolist()), vec3(p.tolist()))


@pytest.fixture(scope="module")
def chains(tmp_path_factory):
    path = tmp_path_factory.mktemp("arms") / "two_arms.yaml"
    path.write_text(ARMS)
    arms = eomgen.load(path)
    kin = derive_frames(arms, ["a3", "b4"]).evaluate(Q_STAR)
    Ra3, pa3, Rb, pb = kin["a3"]["R"], kin["a3"]["p"], kin["b4"]["R"], kin["b4"]["p"]
    # frame b: b4's own frame (on jb4's axis); frame a on a3 where b4 is at q*
    pose = (Ra3.T @ Rb, Ra3.T @ (pb - pa3))
    Ra = Rb
    weld = replace(arms, loops=(Loop("tip", WELD, LoopFrame("a3", _transform(*pose)),
                                     LoopFrame("b4")),), actuated=("ja1",))
    # the hinge: jb4 cut out, frame b on b3 at jb4's placement at q*_7, its axis K (b4's)
    c, s = np.cos(Q_STAR[6]), np.sin(Q_STAR[6])
    k = K / np.linalg.norm(K)
    Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    R4 = np.eye(3) + s * Kx + (1 - c) * Kx @ Kx  # jb4's origin is [0.2, 0, 0] in b3
    to_b = _transform(R4, np.array([0.2, 0.0, 0.0]))
    # for the comparison b4 is massless (the forces through the cut are then jb4's)
    light = replace(weld, links=arms.links[:-1] + (replace(arms.links[-1], inertial=None),))
    no_b4 = replace(arms, links=arms.links[:-1], joints=arms.joints[:-1])
    hinge = replace(no_b4, loops=(Loop("tip", HINGE, LoopFrame("a3", _transform(*pose)),
                                       LoopFrame("b3", to_b), tuple(k)),), actuated=("ja1",))
    return LoopDynamics(weld), LoopDynamics(hinge), Ra, LoopDynamics(light)


def _state(dyn, q, seed):
    rng = np.random.default_rng(seed)
    J = dyn.loop_jacobian(q)
    N = np.linalg.svd(J)[2][np.linalg.matrix_rank(J):].T
    return N @ rng.uniform(-1, 1, N.shape[1]), rng.uniform(-1, 1, len(q))


def test_the_chain_is_closed_at_q_star(chains):
    weld, hinge, _, _ = chains
    assert np.abs(weld.loop_constraint(Q_STAR)).max() < 1e-12
    assert np.abs(hinge.loop_constraint(Q_STAR[:6])).max() < 1e-12
    assert weld.loop_jacobian(Q_STAR).shape == (6, 7) and hinge.loop_jacobian(Q_STAR[:6]).shape == (5, 6)


def test_weld_against_pinocchio_6d(chains):
    pin = need("pinocchio")
    from eomgen.numeric.loops import pinocchio_loops
    from eomgen.numeric.pinocchio import to_pinocchio

    weld, _, Ra, _ = chains
    qd, tau = _state(weld, Q_STAR, 0)
    qdd, lam = weld.constrained_forward_dynamics(Q_STAR, qd, tau)
    pm = to_pinocchio(weld.model)
    p = pm.perm
    models = pinocchio_loops(weld.model, pm)
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm.model, pm.data, models, datas)
    a = pin.constraintDynamics(pm.model, pm.data, Q_STAR[p], qd[p], tau[p], models, datas,
                               pin.ProximalSettings(1e-14, 0.0, 100))
    qdd_pin = np.empty(7)
    qdd_pin[p] = a
    R = datas[0].oMc1.rotation
    assert np.allclose(R, Ra, atol=1e-12)
    lam_pin = -np.concatenate([R @ pm.data.lambda_c[:3], R @ pm.data.lambda_c[3:]])
    scale = np.abs(qdd).max()
    assert np.abs(qdd - qdd_pin).max() <= 1e-8 * scale
    assert np.abs(lam - lam_pin).max() <= 1e-8 * np.abs(lam).max()


def test_hinge_is_the_weld_with_its_joint_cut(chains):
    _, hinge, Ra, weld = chains
    qd, tau = _state(weld, Q_STAR, 1)
    tau[6] = 0.0  # the cut joint is free
    qdd_w, lam_w = weld.constrained_forward_dynamics(Q_STAR, qd, tau)
    qdd_h, lam_h = hinge.constrained_forward_dynamics(Q_STAR[:6], qd[:6], tau[:6])
    assert np.abs(qdd_h - qdd_w[:6]).max() <= 1e-9 * np.abs(qdd_w).max()
    assert np.abs(lam_h[:3] - lam_w[:3]).max() <= 1e-9 * np.abs(lam_w).max()
    u = [Ra @ t for t in (np.array(x, dtype=float) for x in plane_axes(hinge.model.loops[0].axis))]
    moment = lam_w[3:]
    axis = Ra @ np.asarray(hinge.model.loops[0].axis)
    assert abs(moment @ axis) <= 1e-9 * np.abs(moment).max()  # the free joint carries none
    assert np.allclose(lam_h[3:], [ui @ moment for ui in u], atol=1e-9 * np.abs(moment).max())


def test_bias_by_finite_differences(chains):
    for dyn, q in ((chains[0], Q_STAR), (chains[1], Q_STAR[:6])):
        qd = np.random.default_rng(3).uniform(-1, 1, len(q))  # any velocity: J_l-dot qd exact
        h = 1e-6
        Jdot_qd = (dyn.loop_jacobian(q + h * qd) - dyn.loop_jacobian(q - h * qd)) / (2 * h) @ qd
        assert np.abs(dyn.loop_bias(q, qd) - Jdot_qd).max() < 1e-7
