"""eomgen.numeric and the mpmath Newton–Euler on quaternion joints (a free flyer, ball joints):
q of NQ entries and v of NV, Pinocchio's layout.

References: Pinocchio's rnea, crba, nonLinearEffects, aba, kinetic and potential energy and
frame placements, with the same arrays, on solo12 read by Pinocchio's own URDF reader with its
own JointModelFreeFlyer; on a tree with ball joints, Pinocchio's JointModelSpherical (the model
built joint by joint by eomgen.numeric.pinocchio.to_pinocchio); the derived program (verify, and
the 40-digit program of eomgen bench's reference).
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model.floating import add_free_flyer
from eomgen.model import Joint, JointType, Link, Transform, build_model, mat3, vec3
from eomgen.numeric import (M_crba, M_rnea, coriolis_times_qd, forward_dynamics, gravity_torques,
                            kinetic_energy, link_poses, numeric_model, potential_energy, rnea)
from support import erd_robots_or_skip, load_quietly, relative
from support.reference import random_inertial, random_rotation
from support.extras import need

pin = need("pinocchio", reason="quaternion joints are checked against Pinocchio")

#: A tree with two ball joints and a branch: (name, type, parent index), on a free flyer.
TREE = (("j0", JointType.REVOLUTE, -1), ("ball", JointType.SPHERICAL, 0),
        ("j2", JointType.PRISMATIC, 1), ("ball2", JointType.SPHERICAL, 1),
        ("j4", JointType.REVOLUTE, 3))


def ball_tree(spec=TREE, seed=1, free_flyer=True):
    """Random placements, axes and inertias on ``spec``; gravity off the z axis."""
    rng = np.random.default_rng(seed)
    links, joints = [Link("trunk", random_inertial(rng))], []
    for name, kind, parent in spec:
        axis = rng.normal(size=3)
        links.append(Link(f"link_{name}", random_inertial(rng)))
        joints.append(Joint(name, kind, "trunk" if parent < 0 else f"link_{spec[parent][0]}",
                            f"link_{name}",
                            Transform(mat3(random_rotation(rng).tolist()),
                                      vec3(rng.uniform(-0.5, 0.5, 3).tolist())),
                            vec3((axis / np.linalg.norm(axis)).tolist())))
    model = build_model("<test>", "ball_tree", links, joints, gravity=vec3([0.3, -0.2, -9.81]))
    return add_free_flyer(model) if free_flyer else model


@pytest.fixture(scope="module")
def solo():
    urdf = erd_robots_or_skip() / "solo_description" / "robots" / "solo12.urdf"
    model = add_free_flyer(load_quietly(urdf))
    pm = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    assert list(pm.names[2:]) == list(model.joint_names[6:])  # the arrays are the same
    return model, pm


@pytest.fixture(scope="module")
def balls():
    from eomgen.numeric.pinocchio import to_pinocchio

    model = ball_tree()
    adapter = to_pinocchio(model)
    assert adapter.identity  # Pinocchio's q and v are eomgen's, entry for entry
    return model, adapter.model


def states(pm, count=3, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        pin.seed(int(rng.integers(1 << 30)))
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


@pytest.mark.parametrize("case", ["solo", "balls"])
def test_dynamics_equal_pinocchio(case, request):
    model, pm = request.getfixturevalue(case)
    nm, data = numeric_model(model), pm.createData()
    assert (nm.nq, nm.n) == (pm.nq, pm.nv) == (model.nq, model.dof)
    for q, v, a in states(pm):
        tau = pin.rnea(pm, data, q, v, a)
        M = pin.crba(pm, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        h = pin.nonLinearEffects(pm, data, q, v)
        g = pin.computeGeneralizedGravity(pm, data, q)
        assert relative(rnea(nm, q, v, a), tau) < 1e-12
        assert relative(M_rnea(nm, q), M) < 1e-12
        assert relative(M_crba(nm, q), M) < 1e-12
        assert relative(gravity_torques(nm, q), g) < 1e-12
        assert relative(coriolis_times_qd(nm, q, v) + gravity_torques(nm, q), h) < 1e-12
        qdd = forward_dynamics(nm, q, v, tau)
        assert relative(qdd, pin.aba(pm, data, q, v, tau)) < 1e-9
        assert relative(qdd, a) < 1e-9
        K = pin.computeKineticEnergy(pm, data, q, v)
        P = pin.computePotentialEnergy(pm, data, q)
        assert abs(kinetic_energy(nm, q, v) - K) < 1e-12 * max(1.0, abs(K))
        assert abs(potential_energy(nm, q) - P) < 1e-12 * max(1.0, abs(P))


def test_link_poses_equal_pinocchios_frames(solo):
    model, pm = solo
    nm, data = numeric_model(model), pm.createData()
    q, _, _ = next(states(pm, seed=5))
    pin.framesForwardKinematics(pm, data, q)
    poses = link_poses(nm, q)
    for link in ("base_link", "FL_FOOT", "HR_LOWER_LEG"):
        placement = data.oMf[pm.getFrameId(link)]
        R, p = poses[link]
        assert np.abs(R - placement.rotation).max() < 1e-13
        assert np.abs(p - placement.translation).max() < 1e-13


def test_non_unit_quaternions_are_normalised(balls):
    model, pm = balls
    nm = numeric_model(model)
    q, v, a = next(states(pm, seed=3))
    scaled = q.copy()
    for joint in model.quaternion_joints:
        scaled[joint.quaternion:joint.quaternion + 4] *= 1.7
    assert relative(rnea(nm, scaled, v, a), rnea(nm, q, v, a)) < 1e-13
    assert relative(M_rnea(nm, scaled), M_rnea(nm, q)) < 1e-13


def test_sizes_are_checked(balls):
    model, _ = balls
    nm = numeric_model(model)
    with pytest.raises(ValueError, match=r"q must have shape \(18,\)"):
        rnea(nm, np.zeros(nm.n), np.zeros(nm.n), np.zeros(nm.n))


def test_verify_checks_a_quaternion_model():
    """eomgen.verify (and so teach's check) on a free flyer with a ball joint: the derived
    program against the float Newton–Euler; a C without the chart correction would fail the
    skew check, which takes Ṁ along the configuration rate. And the generated NumPy functions
    against eomgen.numeric directly."""
    spec = (("ball", JointType.SPHERICAL, -1), ("knee", JointType.REVOLUTE, 0))
    model = ball_tree(spec, seed=4)
    dynamics = eomgen.derive(model, outputs=("M", "C", "g", "tau"))
    report = eomgen.verify(dynamics, samples=4)
    assert report.passed, report.format()
    assert {c.how for c in report.checks} >= {"4 samples"}
    f, nm = dynamics.lambdify(), numeric_model(model)  # the generated NumPy module's functions
    rng = np.random.default_rng(9)
    for _ in range(2):
        q = rng.normal(size=model.nq)  # a quaternion of any norm: both normalise it
        v, a = rng.normal(size=(2, model.dof))
        assert relative(rnea(nm, q, v, a), f.tau(q, v, a).ravel()) < 1e-12
        assert relative(M_rnea(nm, q), f.M(q)) < 1e-12
        assert relative(coriolis_times_qd(nm, q, v), f.C(q, v) @ v) < 1e-12


def test_mpmath_references_agree_on_quaternion_joints():
    """The bench's two 40-digit references (the derived program, the mpmath Newton–Euler) on a
    free flyer with a ball joint, and the float64 recursion against them."""
    need("mpmath")
    from eomgen.analysis.bench import sample_states
    from eomgen.analysis.precision import Reference, relative_error

    model = ball_tree((("ball", JointType.SPHERICAL, -1), ("knee", JointType.REVOLUTE, 0)),
                      seed=6)
    q, v, a = sample_states(model.dof, 2, 0, model)
    assert q.shape == (2, model.nq) and v.shape == (2, model.dof)
    for joint in model.quaternion_joints:  # unit quaternions
        assert np.allclose(np.linalg.norm(q[:, joint.quaternion:joint.quaternion + 4], axis=1), 1)
    reference = Reference(model)
    assert reference.cross_check(list(zip(q, v, a))) < 1e-30
    nm = numeric_model(model)
    assert relative_error(rnea(nm, q[0], v[0], a[0]), reference.tau(q[0], v[0], a[0])) < 1e-14
    assert relative_error(M_rnea(nm, q[1]), reference.M(q[1])) < 1e-14
    assert relative_error(M_crba(nm, q[1]), reference.M(q[1])) < 1e-14
    import mpmath
    from eomgen.analysis.precision import max_abs
    with mpmath.workdps(reference.dps):  # the CRBA in mpmath, against the derived program
        M = reference.M(q[0])
        assert max_abs(M_crba(reference.mp_model, q[0]) - M) / max_abs(M) < 1e-30


@pytest.mark.slow
def test_bench_measures_a_ball_joint(tmp_path):
    """``eomgen bench`` of a pendulum on a ball joint (it refused quaternion joints): every
    float64 route within rounding of the 40-digit reference, which its two evaluations agree
    on."""
    need("matplotlib", reason="eomgen bench")
    need("mpmath", reason="eomgen bench")
    import csv

    from support import run_in_process
    path = tmp_path / "pendulum.yaml"
    path.write_text("name: pendulum\nlinks:\n  - {name: base}\n  - {name: upper, mass: 1, "
                    "com: [0.1, 0, -0.5], inertia: {ixx: 0.02, iyy: 0.03, izz: 0.01}}\n"
                    "joints:\n  - {name: shoulder, type: spherical, parent: base, "
                    "child: upper}\n", encoding="utf-8")
    result = run_in_process("bench", path, "-o", tmp_path / "out", "--samples", "3",
                            "--repeats", "1", "--batch-size", "3", "--quiet")
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((tmp_path / "out" / "bench_pendulum.csv").open(encoding="utf-8")))
    routes = {row["route"] for row in rows}
    assert {"RNEA (eomgen.numeric)", "NumPy, batch"} <= routes
    for row in rows:
        assert float(row["error_max"]) < (1e-6 if row["dtype"] == "float32" else 1e-14), row
    assert "agree to" in result.stdout
