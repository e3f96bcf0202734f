"""The five-bar and the Delta robot (examples/robots/, closed by examples/loops/), and the
five-bar welded in the plane, against Pinocchio's ``constraintDynamics`` with loop
``RigidConstraintModel``s between two joints (``CONTACT_3D`` or ``CONTACT_6D``, ``LOCAL``): q̈
and the loop forces within 1e-8 relative. Pinocchio's
``lambda_c`` is the force on joint 1's side (the loop's frame a) in frame a's axes; eomgen's λ
is the force on frame b in world axes: ``λ = −R_a λ_pin``.

Also the parallel inverse dynamics (the actuated efforts and loop forces that give back a
constrained motion), and contacts and loops in one KKT system (generated).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import eomgen
from eomgen.numeric.loops import LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT, relative
from support.extras import need

ROBOTS = {"fivebar": ("fivebar_loop", [1.2, 1.0, 1.9, -1.0]),
          "delta": ("delta_loops", [0.3, 2.13, 0.0] * 3 + [0.0, 0.0, -0.35])}


def _model(robot: str, extra: str = ""):
    scene, _ = ROBOTS[robot]
    text = (ROOT / f"examples/loops/{scene}.yaml").read_text() + extra
    return apply_scene(eomgen.load(ROOT / f"examples/robots/{robot}.yaml"),
                       load_scene(f"{scene}.yaml", text=text)).model


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def robot(request):
    dyn = LoopDynamics(_model(request.param))
    return request.param, dyn, dyn.assemble(ROBOTS[request.param][1])


def _states(dyn, q0, count=2, seed=0):
    """Closed configurations near ``q0`` (motors moved, passive joints by Newton), velocities in
    the null space of J_l, random efforts."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        q = q0.copy()
        q[dyn.actuated] += rng.uniform(-0.15, 0.15, len(dyn.actuated))
        q = dyn.assemble(q)
        J = dyn.loop_jacobian(q)
        N = np.linalg.svd(J)[2][np.linalg.matrix_rank(J):].T
        out.append((q, N @ rng.uniform(-1, 1, N.shape[1]), rng.uniform(-1, 1, len(q))))
    return out


def test_against_pinocchio_constraint_dynamics(robot):
    pin = need("pinocchio")
    from eomgen.numeric.loops import pinocchio_loops
    from eomgen.numeric.pinocchio import to_pinocchio

    name, dyn, q0 = robot
    pm = to_pinocchio(dyn.model)
    p = pm.perm
    models = pinocchio_loops(dyn.model, pm)
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm.model, pm.data, models, datas)
    # mu = 0: the exact KKT system; the planar five-bar's third rows are dependent, so a
    # proximal mu there (its iterations converge to the exact solution)
    settings = pin.ProximalSettings(1e-14, 1e-12 if name == "fivebar" else 0.0, 100)
    for q, qd, tau in _states(dyn, q0):
        qdd, lam = dyn.constrained_forward_dynamics(q, qd, tau)
        a = pin.constraintDynamics(pm.model, pm.data, q[p], qd[p], tau[p], models, datas,
                                   settings)
        qdd_pin = np.empty_like(qdd)
        qdd_pin[p] = a
        assert relative(qdd, qdd_pin) <= 1e-8, name
        forces = []
        for k, data in enumerate(datas):
            f = -data.oMc1.rotation @ pm.data.lambda_c[3 * k:3 * k + 3]
            forces.append(f[:2] if dyn.model.loops[k].plane is not None else f)
        assert relative(lam, np.concatenate(forces)) <= 1e-8, name


def test_parallel_inverse_dynamics_gives_back_the_motion(robot):
    """With efforts on the actuated joints only, the constrained forward dynamics' q̈ fed to
    the parallel inverse dynamics gives back those efforts and the same loop forces (the square
    system [S^T J_l^T]: n_a + m_l = n for both robots)."""
    name, dyn, q0 = robot
    assert len(dyn.actuated) + dyn.loop_jacobian(q0).shape[0] == dyn.model.dof
    for q, qd, tau in _states(dyn, q0, count=1, seed=1):
        tau[dyn.passive] = 0.0
        qdd, lam = dyn.constrained_forward_dynamics(q, qd, tau)
        tau_a, lam_id = dyn.parallel_inverse_dynamics(q, qd, qdd)
        assert relative(tau_a, tau[dyn.actuated]) <= 1e-9, name
        assert relative(lam_id, lam) <= 1e-9, name


def test_contacts_and_loops_in_one_kkt_system(tmp_path):
    """The five-bar's elbows also held by point contacts (world rows x, y, z, of rank 1 each:
    an elbow moves on a circle; the damped solve): the generated J_c stacks the contact rows
    then the loop rows, and its KKT solution holds both (q̈ = 0: the 4 independent rows lock
    the 4 joints) and matches the numeric one."""
    from support.generated import generated

    model = _model("fivebar", "contacts:\n  - {frame: left_distal, name: left}\n"
                   "  - {frame: right_distal, name: right}\n")
    dyn = LoopDynamics(model)
    q = dyn.assemble(ROBOTS["fivebar"][1])
    _, modules = generated(model, ["constrained_forward_dynamics"], tmp_path, ("numpy",))
    module = modules["numpy"]
    assert tuple(module["CONTACT_ROWS"]) == ("left.f_x", "left.f_y", "left.f_z", "right.f_x",
                                             "right.f_y", "right.f_z", "effector.u",
                                             "effector.v")
    tau = np.array([0.3, 0.0, -0.2, 0.0])
    qdd, F = module["constrained_forward_dynamics"](q, np.zeros(4), tau, damping=1e-12)
    qdd_ref, F_ref = dyn.constrained_forward_dynamics(q, np.zeros(4), tau, damping=1e-12)
    e = dyn.evaluate(q)
    # an elbow contact's radial force is the pivot's (not unique): compare J_c^T F and the
    # loop forces, which are
    assert np.abs(qdd).max() < 1e-9 and relative(F[-2:], F_ref[-2:]) < 1e-8
    assert relative(e["J_c"].T @ F, e["J_c"].T @ F_ref) < 1e-8
    # statics: g = tau + J_c^T F
    np.testing.assert_allclose(module["contact_jacobian"](q), e["J_c"], atol=1e-14)
    assert np.abs(e["J_c"].T @ F + tau - e["h"]).max() < 1e-9


def test_generated_parallel_inverse_dynamics(tmp_path):
    """The NumPy and fast modules' parallel_inverse_dynamics on the Delta: the efforts that
    produced a constrained motion (zero on the passive joints) and its loop forces, one state
    and a batch (the other backends: test_parallel_outputs.py)."""
    from support.generated import generated

    model = _model("delta")
    dyn = LoopDynamics(model)
    (q, qd, tau), = _states(dyn, dyn.assemble(ROBOTS["delta"][1]), count=1, seed=2)
    tau[dyn.passive] = 0.0
    qdd, lam = dyn.constrained_forward_dynamics(q, qd, tau)
    _, modules = generated(model, ["parallel_inverse_dynamics"], tmp_path, ("numpy", "fast"))
    if "fast" not in modules:
        pytest.skip("no C compiler: the fast module was not built")
    for backend, module in modules.items():
        assert tuple(module["ACTUATED_JOINTS"]) == ("motor1", "motor2", "motor3")
        f = module["parallel_inverse_dynamics"]
        t, l = (np.asarray(x) for x in f(q, qd, qdd))
        assert relative(t, tau) < 1e-9 and relative(l, lam) < 1e-9, backend
        t2, l2 = f(np.array([q, q]), np.array([qd, qd]), np.array([qdd, qdd]))
        assert np.allclose(t2[1], t) and np.allclose(l2[1], l), backend
        with pytest.raises(FloatingPointError, match="not finite"), np.errstate(invalid="ignore"):
            f(np.full(12, np.inf), qd, qdd)


def test_planar_weld_against_pinocchio_6d():
    """The five-bar's distal links welded in the plane (rows u, v, rn: 3 of 4 joints held):
    against Pinocchio's CONTACT_6D between them, whose 3 out-of-plane rows are dependent (a
    proximal mu), q̈ and the in-plane force and moment."""
    pin = need("pinocchio")
    from eomgen.model import WELD, Loop, LoopFrame, Transform, mat3, vec3
    from eomgen.numeric.loops import pinocchio_loops
    from eomgen.numeric.pinocchio import to_pinocchio
    from eomgen.symbolic.frames import derive_frames

    base = _model("fivebar")
    q_star = LoopDynamics(base).assemble(ROBOTS["fivebar"][1])
    kin = derive_frames(base, ["left_distal", "right_distal"]).evaluate(q_star)
    La, Rb = kin["left_distal"], kin["right_distal"]
    tip = La["p"] + La["R"] @ np.array([0.3, 0, 0])
    pose = Transform(mat3((Rb["R"].T @ La["R"]).tolist()),
                     vec3((Rb["R"].T @ (tip - Rb["p"])).tolist()))
    loop = Loop("effector", WELD, LoopFrame("left_distal",
                                            Transform(translation=vec3([0.3, 0, 0]))),
                LoopFrame("right_distal", pose), plane=(0.0, 0.0, 1.0))
    dyn = LoopDynamics(replace(base, loops=(loop,)))
    assert dyn.loop_jacobian(q_star).shape == (3, 4)
    assert np.abs(dyn.loop_constraint(q_star)).max() < 1e-12
    qd = np.linalg.svd(dyn.loop_jacobian(q_star))[2][3:].T @ np.array([0.7])
    tau = np.array([0.4, -0.3, 0.2, 0.1])
    qdd, lam = dyn.constrained_forward_dynamics(q_star, qd, tau)
    pm = to_pinocchio(dyn.model)
    p = pm.perm
    models = pinocchio_loops(dyn.model, pm)
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm.model, pm.data, models, datas)
    a = pin.constraintDynamics(pm.model, pm.data, q_star[p], qd[p], tau[p], models, datas,
                               pin.ProximalSettings(1e-14, 1e-12, 100))
    qdd_pin = np.empty(4)
    qdd_pin[p] = a
    R = datas[0].oMc1.rotation
    force, moment = -R @ pm.data.lambda_c[:3], -R @ pm.data.lambda_c[3:]
    assert relative(qdd, qdd_pin) <= 1e-8
    assert relative(lam, np.array([force[0], force[1], moment[2]])) <= 1e-8
