"""eomgen.numeric on coupled joints (issue 26): the float and mpmath Newton–Euler take the
independent coordinates, run the whole tree at q = T q_r + c, and project; ``eomgen bench`` and
``eomgen simulate`` run the Panda with its <mimic> fingers free (8 coordinates).

References: Pinocchio's mimic model of the Panda (``buildModelFromUrdf(path, mimic=True)``) for
rnea, crba, nonLinearEffects, gravity and the energies; the symbolic reduced model (the
derived program) on a differential whose gains and offset are not 1 and 0.
"""

from __future__ import annotations

import csv
import warnings

import numpy as np
import pytest

import eomgen
from eomgen.model import couple
from eomgen.numeric import (M_crba, M_rnea, coriolis_times_qd, gravity_torques, kinetic_energy,
                            numeric_model, potential_energy, rnea)
from support import erd_robots_or_skip, relative, run_cli
from support.extras import need


@pytest.fixture(scope="module")
def panda():
    path = erd_robots_or_skip() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return path, eomgen.load(path)


def test_panda_mimic_equals_pinocchio(panda):
    pin = need("pinocchio", reason="Pinocchio's mimic joints are the reference")
    path, model = panda
    nm = numeric_model(model)
    assert (nm.n, nm.nq, nm.n_tree) == (8, 8, 9)
    pm = pin.buildModelFromUrdf(str(path), mimic=True)
    data, tree = pm.createData(), pin.buildModelFromUrdf(str(path))
    assert [n for n in pm.names[1:] if n in model.joint_names] == list(model.joint_names)
    rng = np.random.default_rng(8)
    for _ in range(3):
        q = np.append(rng.uniform(-1.5, 1.5, 7), rng.uniform(0, 0.04))
        v, a = rng.normal(size=(2, 8))
        M = pin.crba(pm, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        assert relative(rnea(nm, q, v, a), pin.rnea(pm, data, q, v, a)) < 1e-12
        assert relative(M_rnea(nm, q), M) < 1e-12
        assert relative(M_crba(nm, q), M) < 1e-12
        assert relative(coriolis_times_qd(nm, q, v) + gravity_torques(nm, q),
                        pin.nonLinearEffects(pm, data, q, v)) < 1e-12
        assert relative(gravity_torques(nm, q), pin.computeGeneralizedGravity(pm, data, q)) < 1e-12
        assert abs(kinetic_energy(nm, q, v) - 0.5 * v @ M @ v) < 1e-12 * (1 + v @ M @ v)
        # Pinocchio's energies refuse mimic joints: P of the whole tree, finger2 = finger1;
        # it leaves out the fixed root link's constant term, so compare P(q) − P(0)
        P = pin.computePotentialEnergy(tree, tree.createData(), np.append(q, q[7]))
        P0 = pin.computePotentialEnergy(tree, tree.createData(), np.zeros(9))
        ours = potential_energy(nm, q) - potential_energy(nm, np.zeros(8))
        assert abs(ours - (P - P0)) < 1e-12 * (1 + abs(P))


def test_differential_equals_the_symbolic_reduced_model():
    """q3 = 0.5 q1 − 0.3 q2 + 0.1 on the elbow arm: float and mpmath Newton–Euler against the
    derived reduced program (its M, C, g, tau), and against the 40-digit reference."""
    arm = eomgen.load(eomgen.example_path("elbow_rrr"))
    model = couple(arm, "elbow", {"waist": 0.5, "shoulder": -0.3}, offset=0.1)
    f = eomgen.derive(model, ("M", "C", "g", "tau")).lambdify()
    nm = numeric_model(model)
    rng = np.random.default_rng(2)
    for _ in range(3):
        q, v, a = rng.uniform(-2, 2, (3, 2))
        assert relative(rnea(nm, q, v, a), f.tau(q, v, a).ravel()) < 1e-12
        assert relative(M_rnea(nm, q), f.M(q)) < 1e-12
        assert relative(coriolis_times_qd(nm, q, v), f.C(q, v) @ v) < 1e-12
        assert relative(gravity_torques(nm, q), f.g(q).ravel()) < 1e-12
    need("mpmath")
    from eomgen.analysis.precision import Reference, relative_error

    reference = Reference(model)
    assert reference.cross_check([(q, v, a)]) < 1e-30
    assert relative_error(rnea(nm, q, v, a), reference.tau(q, v, a)) < 1e-14


def test_verify_and_simulate_a_coupled_model(tmp_path):
    """eomgen verify on the differential, and eomgen simulate's study on it (it refused coupled
    models: its energy comes from eomgen.numeric): DOP853 keeps that energy."""
    need("scipy", reason="eomgen simulate")
    need("matplotlib", reason="eomgen simulate")
    arm = eomgen.load(eomgen.example_path("elbow_rrr"))
    model = couple(arm, "elbow", {"waist": 0.5, "shoulder": -0.3}, offset=0.1)
    report = eomgen.verify(eomgen.derive(model, ("M", "C", "g")), samples=3)
    assert report.passed, report.format()
    from eomgen.analysis.simulate import Adaptive, run_study

    study = run_study(model, [Adaptive("DOP853", 1e-10)], 1.0, [0.4, -0.7], [0.5, 1.0])
    run, = study.runs
    assert run.status == "ok" and run.relative_energy_drift < 1e-8


@pytest.mark.slow
def test_bench_runs_the_panda_with_its_mimic_fingers(panda, tmp_path):
    """``eomgen bench`` refused the Panda (eomgen.numeric had no coupling map): every route
    within rounding of the 40-digit reference, Pinocchio's through the whole tree (T q + c,
    projected by Tᵀ). simulate: test_verify_and_simulate_a_coupled_model."""
    need("matplotlib", reason="eomgen bench")
    need("mpmath", reason="eomgen bench")
    path, _ = panda
    result = run_cli("bench", str(path), "--samples", "2", "--repeats", "1", "--batch-size",
                     "2", "--quiet", "-o", str(tmp_path / "bench"))
    assert result.exit_code == 0, result.output
    with open(tmp_path / "bench" / "bench_panda.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert {"RNEA (eomgen.numeric)", "Pinocchio"} <= {row["route"] for row in rows}
    for row in rows:
        assert float(row["error_max"]) < (1e-5 if row["dtype"] == "float32" else 1e-13), row


def test_frame_jacobians_of_a_coupled_model_are_derivatives_of_the_pose():
    """eomgen.numeric.frames on the differential: J = J_tree T is the central difference of
    the tip's position and rotation along each independent coordinate."""
    from eomgen.numeric.frames import frame_kinematics

    arm = eomgen.load(eomgen.example_path("elbow_rrr"))
    model = couple(arm, "elbow", {"waist": 0.5, "shoulder": -0.3}, offset=0.1)
    nm = numeric_model(model)
    tip = nm.body_names[-1]
    q = np.array([0.4, -0.9])
    J = frame_kinematics(nm, q, frames=[tip])[tip]["J"]
    assert J.shape == (6, 2)
    h = 1e-6
    for k in range(2):
        e = np.eye(2)[k] * h
        plus, minus = (frame_kinematics(nm, q + s * e, frames=[tip])[tip] for s in (1, -1))
        assert np.abs((plus["p"] - minus["p"]) / (2 * h) - J[:3, k]).max() < 1e-8
        W = (plus["R"] - minus["R"]) / (2 * h) @ frame_kinematics(nm, q, frames=[tip])[tip]["R"].T
        assert np.abs(np.array([W[2, 1], W[0, 2], W[1, 0]]) - J[3:, k]).max() < 1e-8


def test_panda_with_a_free_flyer_and_mimic_fingers_equals_pinocchio(panda):
    """Couplings on a quaternion model: q (NQ = 15) maps to the whole tree's configuration
    (NQ = 16) with the free flyer's seven entries copied; against Pinocchio's free flyer with
    mimic joints, arrays unchanged."""
    pin = need("pinocchio", reason="Pinocchio's mimic joints are the reference")
    from eomgen.model.floating import add_free_flyer
    from eomgen.numeric.frames import frame_kinematics

    path, model = panda
    model = add_free_flyer(model)
    nm = numeric_model(model)
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer(), mimic=True)
    data = pm.createData()
    assert (nm.nq, nm.n) == (pm.nq, pm.nv) == (15, 14)
    rng = np.random.default_rng(4)
    pin.seed(4)
    for _ in range(2):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        v, a = rng.normal(size=(2, pm.nv))
        M = pin.crba(pm, data, q)
        assert relative(rnea(nm, q, v, a), pin.rnea(pm, data, q, v, a)) < 1e-12
        assert relative(M_rnea(nm, q), np.triu(M) + np.triu(M, 1).T) < 1e-12
        assert relative(M_crba(nm, q), np.triu(M) + np.triu(M, 1).T) < 1e-12
        pin.computeJointJacobians(pm, data, q)
        pin.updateFramePlacements(pm, data)
        frame = pm.getFrameId("panda_rightfinger")
        J = pin.getFrameJacobian(pm, data, frame, pin.LOCAL_WORLD_ALIGNED)
        assert relative(frame_kinematics(nm, q, v, ["panda_rightfinger"])[
            "panda_rightfinger"]["J"], J) < 1e-12


def test_a_coupling_across_a_ball_joint_maps_by_name():
    """A revolute joint after a ball joint follows one before it (q_j4 = −0.7 q_j0 + 0.2):
    the coupled recursion equals the whole tree's at the configuration built entry by entry
    from the names (the ball's quaternion copied), projected by Tᵀ; eomgen verify passes."""
    from eomgen.model import Joint, JointType, Link, Transform, build_model, mat3, uncoupled, vec3
    from support.reference import random_inertial, random_rotation

    rng = np.random.default_rng(12)
    spec = (("j0", JointType.REVOLUTE, "trunk"), ("ball", JointType.SPHERICAL, "l_j0"),
            ("j2", JointType.PRISMATIC, "l_ball"), ("j4", JointType.REVOLUTE, "l_j2"))
    links = [Link("trunk", random_inertial(rng))]
    joints = []
    for name, kind, parent in spec:
        axis = rng.normal(size=3)
        links.append(Link(f"l_{name}", random_inertial(rng)))
        joints.append(Joint(name, kind, parent, f"l_{name}",
                            Transform(mat3(random_rotation(rng).tolist()),
                                      vec3(rng.uniform(-0.4, 0.4, 3).tolist())),
                            vec3((axis / np.linalg.norm(axis)).tolist())))
    tree = build_model("<test>", "ball_differential", links, joints)
    model = couple(tree, "j4", "j0", ratio=-0.7, offset=0.2)
    nm, whole = numeric_model(model), numeric_model(uncoupled(model))
    assert model.joint_names == ("j0", "ball_wx", "ball_wy", "ball_wz", "j2")
    quaternion = rng.normal(size=4)
    q = np.concatenate([[0.3], quaternion / np.linalg.norm(quaternion), [0.1]])
    values = dict(zip(model.configuration_names, q))
    values["j4"] = -0.7 * values["j0"] + 0.2
    q_tree = np.array([values[name] for name in tree.configuration_names])
    T = np.zeros((6, 5))
    T[:5, :5] = np.eye(5)
    T[5, 0] = -0.7
    v, a = rng.normal(size=(2, 5))
    assert relative(rnea(nm, q, v, a), T.T @ rnea(whole, q_tree, T @ v, T @ a)) < 1e-13
    assert relative(M_rnea(nm, q), T.T @ M_rnea(whole, q_tree) @ T) < 1e-13
    assert abs(potential_energy(nm, q) - potential_energy(whole, q_tree)) < 1e-13
    # and eomgen verify: the derived program of the coupled quaternion model against it
    report = eomgen.verify(eomgen.derive(model, ("M", "C", "g")), samples=3)
    assert report.passed, report.format()
