"""The numeric recursive Newton–Euler algorithm (eomgen.numeric) against independent references:
Pinocchio (models built joint by joint, and through Pinocchio's own URDF reader), closed-form
textbook dynamics, and energy identities."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from eomgen.errors import DescriptionError
from eomgen.model import (
    Inertial,
    Joint,
    JointType,
    Link,
    Parameter,
    Transform,
    build_model,
    mat3,
    parameter_symbol,
    scalar,
    vec3,
)
from eomgen.numeric import (
    NumericModel,
    coriolis_times_qd,
    gravity_torques,
    kinetic_energy,
    link_poses,
    M_rnea,
    numeric_model,
    potential_energy,
    rnea,
)
from support.reference import (
    pin_q_order,
    random_robot,
    to_pinocchio,
    to_urdf,
)
from support import uniform_states
from support.extras import need

pin = need("pinocchio")

RTOL = 1e-10


def assert_close(a, b, rtol=RTOL):
    """``||a - b|| <= rtol * max(1, ||b||)`` (Frobenius norm for matrices)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    assert a.shape == b.shape
    err = np.linalg.norm(a - b)
    assert err <= rtol * max(1.0, np.linalg.norm(b)), f"|a-b| = {err:.3g}\na = {a}\nb = {b}"


def random_state(rng, n, scale=2.0):
    return uniform_states(rng, n, 1, scale=scale)[0]


class PinocchioReference:
    """Our ordering on top of a Pinocchio model: everything in model.joint_names order."""

    def __init__(self, model, pmodel):
        self.pmodel = pmodel
        self.data = pmodel.createData()
        self.perm = pin_q_order(model, pmodel)
        self.inv = np.argsort(self.perm)

    def _vec(self, x):
        return np.asarray(x)[self.perm]

    def _back(self, x):
        return np.asarray(x)[self.inv]

    def rnea(self, q, qd, qdd):
        return self._back(pin.rnea(self.pmodel, self.data, self._vec(q), self._vec(qd),
                                   self._vec(qdd)))

    def mass_matrix(self, q):
        M = pin.crba(self.pmodel, self.data, self._vec(q)).copy()
        M = np.triu(M) + np.triu(M, 1).T
        return M[np.ix_(self.inv, self.inv)]

    def gravity(self, q):
        return self._back(pin.computeGeneralizedGravity(self.pmodel, self.data, self._vec(q)))

    def coriolis_times_qd(self, q, qd):
        C = pin.computeCoriolisMatrix(self.pmodel, self.data, self._vec(q), self._vec(qd))
        return self._back(C @ self._vec(qd))

    def kinetic_energy(self, q, qd):
        return pin.computeKineticEnergy(self.pmodel, self.data, self._vec(q), self._vec(qd))

    def potential_energy(self, q):
        return pin.computePotentialEnergy(self.pmodel, self.data, self._vec(q))

    def frame_poses(self, q):
        pin.framesForwardKinematics(self.pmodel, self.data, self._vec(q))
        return {f.name: self.data.oMf[i] for i, f in enumerate(self.pmodel.frames)}


def static_potential(nm):
    """Potential energy of the bodies welded to the root (no movable joint above them)."""
    static = np.zeros(nm.nb, dtype=bool)
    static[0] = True
    for i in range(1, nm.nb):
        static[i] = static[nm.parent[i]] and nm.q_index[i] < 0
    poses = link_poses(nm, np.zeros(nm.n))
    return -sum(nm.mass[i] * nm.gravity @ (poses[name][0] @ nm.com[i] + poses[name][1])
                for i, name in enumerate(nm.body_names) if static[i])


def robot_cases():
    """(seed, n, tree, prismatic, fixed_links): 1–8 joints, chains and trees."""
    cases = []
    for seed in range(16):
        n = 1 + seed % 8
        cases.append((seed, n, seed % 2 == 1, seed % 5 != 4, seed % 7 != 6))
    return cases


CASES = robot_cases()


def case_id(case):
    return f"seed{case[0]}-n{case[1]}-{'tree' if case[2] else 'chain'}"


def make_robot(seed, n, tree, prismatic, fixed_links):
    rng = np.random.default_rng(1000 + seed)
    return rng, random_robot(rng, n, tree=tree, prismatic=prismatic, fixed_links=fixed_links)


# ----------------------------------------------------------------------------------------------
# Against Pinocchio
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_matches_pinocchio(case):
    rng, model = make_robot(*case)
    nm = numeric_model(model)
    ref = PinocchioReference(model, to_pinocchio(model))
    for _ in range(4):
        q, qd, qdd = random_state(rng, nm.n)
        assert_close(rnea(nm, q, qd, qdd), ref.rnea(q, qd, qdd))
        assert_close(M_rnea(nm, q), ref.mass_matrix(q))
        assert_close(gravity_torques(nm, q), ref.gravity(q))
        assert_close(coriolis_times_qd(nm, q, qd), ref.coriolis_times_qd(q, qd))
        assert_close(kinetic_energy(nm, q, qd), ref.kinetic_energy(q, qd))
        # Pinocchio leaves out the links welded to the root: compare up to that constant.
        assert_close(potential_energy(nm, q) - static_potential(nm), ref.potential_energy(q))


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_matches_pinocchio_urdf_reader(case):
    """Pinocchio's own URDF reader interprets our frame conventions independently of
    to_pinocchio: dynamics and every link's pose must agree."""
    rng, model = make_robot(*case)
    nm = numeric_model(model)
    pmodel = pin.buildModelFromXML(to_urdf(model))
    pmodel.gravity = pin.Motion(nm.gravity.copy(), np.zeros(3))
    ref = PinocchioReference(model, pmodel)
    for _ in range(3):
        q, qd, qdd = random_state(rng, nm.n)
        assert_close(rnea(nm, q, qd, qdd), ref.rnea(q, qd, qdd))
        frames = ref.frame_poses(q)
        for name, (R, p) in link_poses(nm, q).items():
            assert_close(R, frames[name].rotation)
            assert_close(p, frames[name].translation)


@pytest.mark.parametrize("case", CASES[:8], ids=lambda c: f"seed{c[0]}")
def test_link_poses_match_pinocchio_frames(case):
    rng, model = make_robot(*case)
    nm = numeric_model(model)
    ref = PinocchioReference(model, to_pinocchio(model))
    q, _, _ = random_state(rng, nm.n, scale=math.pi)
    poses = link_poses(nm, q)
    assert set(poses) == {link.name for link in model.links}
    frames = ref.frame_poses(q)
    for name, (R, p) in poses.items():
        if name == model.root:
            assert_close(R, np.eye(3))
            assert_close(p, np.zeros(3))
            continue
        assert_close(R, frames[name].rotation)
        assert_close(p, frames[name].translation)


# ----------------------------------------------------------------------------------------------
# Closed forms (no Pinocchio)
# ----------------------------------------------------------------------------------------------


def pendulum(axis=(0, 1, 0)):
    """Point mass m at distance l below a revolute joint; q = 0 hangs straight down."""
    m, l = parameter_symbol("m"), parameter_symbol("l")
    return build_model(
        "<test>", "pendulum",
        [Link("base"), Link("bob", Inertial(m, vec3([0, 0, -l])))],
        [Joint("swing", JointType.REVOLUTE, "base", "bob", Transform(), vec3(axis))],
        parameters=[Parameter(m, 2.0), Parameter(l, 0.75)],
    )


def test_pendulum_closed_form():
    m, l, g = 2.0, 0.75, 9.81
    nm = numeric_model(pendulum())
    rng = np.random.default_rng(0)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-3, 3, size=3)
        # rotation about +y swings the bob towards -x: P = -m g l cos q
        expected = m * l * l * qdd + m * g * l * math.sin(q)
        assert_close(rnea(nm, [q], [qd], [qdd]), [expected])
        assert_close(potential_energy(nm, [q]), -m * g * l * math.cos(q))
        assert_close(kinetic_energy(nm, [q], [qd]), 0.5 * m * l * l * qd * qd)
        assert_close(coriolis_times_qd(nm, [q], [qd]), [0.0])


def test_pendulum_axis_sign_flips_torque():
    nm_plus = numeric_model(pendulum((0, 1, 0)))
    nm_minus = numeric_model(pendulum((0, -1, 0)))
    q = [0.4]
    # about -y the same q swings the bob towards +x; same restoring torque in its own sign
    assert_close(gravity_torques(nm_minus, q), gravity_torques(nm_plus, q))
    R, _ = link_poses(nm_plus, q)["bob"]
    assert_close(R @ nm_plus.com[1], 0.75 * np.array([-math.sin(0.4), 0, -math.cos(0.4)]))
    R, _ = link_poses(nm_minus, q)["bob"]
    assert_close(R @ nm_minus.com[1], 0.75 * np.array([math.sin(0.4), 0, -math.cos(0.4)]))


def test_parameter_values_override_defaults():
    model = pendulum()
    nm = numeric_model(model, {"m": 3.0})
    assert nm.mass[1] == 3.0 and nm.com[1, 2] == -0.75
    nm = numeric_model(model, {parameter_symbol("l"): 2.0})
    assert nm.mass[1] == 2.0 and nm.com[1, 2] == -2.0
    no_default = build_model(
        "<test>", "p", [Link("a"), Link("b", Inertial(parameter_symbol("mystery")))],
        [Joint("j", JointType.REVOLUTE, "a", "b")])
    with pytest.raises(DescriptionError, match="mystery"):
        numeric_model(no_default)


def test_cart_pole_closed_form():
    """Prismatic cart (mass mc, along x) carrying a pendulum (point mass m at l) about y."""
    mc, m, l, g = 1.5, 0.4, 0.6, 9.81
    model = build_model(
        "<test>", "cart_pole",
        [Link("rail"), Link("cart", Inertial(scalar(mc))),
         Link("pole", Inertial(scalar(m), vec3([0, 0, -l])))],
        [Joint("hinge", JointType.CONTINUOUS, "cart", "pole", Transform(), vec3([0, 1, 0])),
         Joint("slide", JointType.PRISMATIC, "rail", "cart", Transform(), vec3([1, 0, 0]))],
    )
    nm = numeric_model(model)
    assert nm.joint_names == ("hinge", "slide")  # description order, not tree order
    rng = np.random.default_rng(1)
    for _ in range(5):
        (th, x), (thd, xd), (thdd, xdd) = random_state(rng, 2)
        F = (mc + m) * xdd - m * l * math.cos(th) * thdd + m * l * math.sin(th) * thd ** 2
        T = -m * l * math.cos(th) * xdd + m * l * l * thdd + m * g * l * math.sin(th)
        assert_close(rnea(nm, [th, x], [thd, xd], [thdd, xdd]), [T, F])
        M = np.array([[m * l * l, -m * l * math.cos(th)], [-m * l * math.cos(th), mc + m]])
        assert_close(M_rnea(nm, [th, x]), M)
        K = 0.5 * (mc + m) * xd ** 2 - m * l * math.cos(th) * xd * thd + 0.5 * m * l * l * thd ** 2
        assert_close(kinetic_energy(nm, [th, x], [thd, xd]), K)


def two_link_arm(m1, m2, l1, lc1, lc2, I1, I2):
    """Planar arm in the x-y plane, joints about z, gravity -y (Spong, Robot Modeling and
    Control, §7.4): link i has its centre of mass lc_i along its x axis."""
    def inertial(m, lc, I):
        inertia = mat3([[0.6 * I, 0, 0], [0, 0.5 * I, 0], [0, 0, I]])
        return Inertial(scalar(m), vec3([lc, 0, 0]), inertia)

    return build_model(
        "<test>", "two_link",
        [Link("base"), Link("link1", inertial(m1, lc1, I1)), Link("link2", inertial(m2, lc2, I2)),
         Link("tip")],
        [Joint("q1", JointType.REVOLUTE, "base", "link1"),
         Joint("q2", JointType.REVOLUTE, "link1", "link2", Transform.from_xyz_rpy([l1, 0, 0])),
         Joint("tool", JointType.FIXED, "link2", "tip", Transform.from_xyz_rpy([0.9, 0, 0]))],
        gravity=[0, -9.81, 0],
    )


def test_planar_two_link_textbook():
    m1, m2, l1, lc1, lc2, I1, I2, g = 1.2, 0.8, 1.0, 0.45, 0.35, 0.11, 0.07, 9.81
    nm = numeric_model(two_link_arm(m1, m2, l1, lc1, lc2, I1, I2))
    rng = np.random.default_rng(2)
    for _ in range(5):
        (q1, q2), (qd1, qd2), qdd = random_state(rng, 2, scale=math.pi)
        c2 = math.cos(q2)
        M = np.array([
            [m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2,
             m2 * (lc2**2 + l1 * lc2 * c2) + I2],
            [m2 * (lc2**2 + l1 * lc2 * c2) + I2, m2 * lc2**2 + I2],
        ])
        h = -m2 * l1 * lc2 * math.sin(q2)
        C = np.array([[h * qd2, h * (qd1 + qd2)], [-h * qd1, 0.0]])
        gv = np.array([
            (m1 * lc1 + m2 * l1) * g * math.cos(q1) + m2 * lc2 * g * math.cos(q1 + q2),
            m2 * lc2 * g * math.cos(q1 + q2),
        ])
        q, qd = np.array([q1, q2]), np.array([qd1, qd2])
        assert_close(M_rnea(nm, q), M)
        assert_close(coriolis_times_qd(nm, q, qd), C @ qd)
        assert_close(gravity_torques(nm, q), gv)
        assert_close(rnea(nm, q, qd, qdd), M @ qdd + C @ qd + gv)
        tip_R, tip_p = link_poses(nm, q)["tip"]
        assert_close(tip_p, [l1 * math.cos(q1) + 0.9 * math.cos(q1 + q2),
                             l1 * math.sin(q1) + 0.9 * math.sin(q1 + q2), 0.0])


def test_description_order_is_q_order():
    """Listing the same chain's joints in another order permutes q and tau, nothing else."""
    rng, model = make_robot(3, 4, False, True, True)
    nm = numeric_model(model)
    reordered = build_model("<test>", "reordered", model.links, reversed(model.joints),
                            gravity=model.gravity)
    nm2 = numeric_model(reordered)
    assert nm2.joint_names == tuple(reversed(nm.joint_names))
    q, qd, qdd = random_state(rng, nm.n)
    r = slice(None, None, -1)
    assert_close(rnea(nm2, q[r], qd[r], qdd[r]), rnea(nm, q, qd, qdd)[r])


# ----------------------------------------------------------------------------------------------
# Energy identities (no Pinocchio)
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"seed{c[0]}")
def test_energy_balance(case):
    """d/dt (K + P) = q̇ᵀ tau along q(t) = q + q̇ t + ½ q̈ t², q̇(t) = q̇ + q̈ t."""
    rng, model = make_robot(*case)
    nm = numeric_model(model)
    q, qd, qdd = random_state(rng, nm.n)

    def energy(t):
        qt, qdt = q + qd * t + 0.5 * qdd * t * t, qd + qdd * t
        return kinetic_energy(nm, qt, qdt) + potential_energy(nm, qt)

    h = 1e-4
    # Richardson extrapolation of central differences: O(h⁴)
    d1 = (energy(h) - energy(-h)) / (2 * h)
    d2 = (energy(2 * h) - energy(-2 * h)) / (4 * h)
    dE = (4 * d1 - d2) / 3
    power = qd @ rnea(nm, q, qd, qdd)
    assert abs(dE - power) <= 1e-7 * max(1.0, abs(power), abs(energy(0.0)))


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"seed{c[0]}")
def test_energy_forms(case):
    """K = ½ q̇ᵀ M q̇; M symmetric positive (semi)definite; g = ∂P/∂q;
    q̇ᵀ C q̇ = ½ q̇ᵀ Ṁ q̇ (skew symmetry of Ṁ − 2C along q̇)."""
    rng, model = make_robot(*case)
    nm = numeric_model(model)
    q, qd, _ = random_state(rng, nm.n)
    M = M_rnea(nm, q)
    assert_close(M, M.T, rtol=1e-12)
    assert np.linalg.eigvalsh(0.5 * (M + M.T)).min() >= -1e-12 * max(1.0, np.abs(M).max())
    assert_close(kinetic_energy(nm, q, qd), 0.5 * qd @ M @ qd, rtol=1e-12)

    h = 1e-6
    grad = np.array([
        (potential_energy(nm, q + h * e) - potential_energy(nm, q - h * e)) / (2 * h)
        for e in np.eye(nm.n)
    ])
    assert_close(grad, gravity_torques(nm, q), rtol=1e-6)

    Mdot = (M_rnea(nm, q + h * qd) - M_rnea(nm, q - h * qd)) / (2 * h)
    assert_close(qd @ coriolis_times_qd(nm, q, qd), 0.5 * qd @ Mdot @ qd, rtol=1e-6)


# ----------------------------------------------------------------------------------------------
# Edge cases and validation
# ----------------------------------------------------------------------------------------------


def test_zero_dof_robot():
    model = build_model(
        "<test>", "statue", [Link("base"), Link("head", Inertial(scalar(1.0), vec3([0, 0, 1])))],
        [Joint("neck", JointType.FIXED, "base", "head", Transform.from_xyz_rpy([0, 0, 2]))])
    nm = numeric_model(model)
    assert nm.n == 0 and nm.nb == 2
    assert rnea(nm, [], [], []).shape == (0,)
    assert M_rnea(nm, []).shape == (0, 0)
    assert_close(potential_energy(nm, []), 9.81 * 3.0)
    assert_close(link_poses(nm, [])["head"][1], [0, 0, 2])


def test_validation_errors():
    nm = numeric_model(two_link_arm(1, 1, 1, 0.5, 0.5, 0.1, 0.1))
    ok = np.zeros(2)
    with pytest.raises(ValueError, match=r"q must have shape \(2,\)"):
        rnea(nm, np.zeros(3), ok, ok)
    with pytest.raises(ValueError, match="qd must have shape"):
        rnea(nm, ok, np.zeros((2, 1)), ok)
    with pytest.raises(ValueError, match="qdd must have shape"):
        rnea(nm, ok, ok, 0.0)
    with pytest.raises(ValueError, match="non-finite"):
        gravity_torques(nm, [0.0, np.nan])
    with pytest.raises(ValueError, match="NumericModel"):
        rnea(two_link_arm(1, 1, 1, 0.5, 0.5, 0.1, 0.1), ok, ok, ok)
    with pytest.raises(ValueError):
        kinetic_energy(nm, ok, [1.0])
    with pytest.raises(ValueError):
        link_poses(nm, [1.0])


def test_bodies_in_depth_first_order():
    """Bodies follow model.topological_joints: depth-first preorder, so every subtree is a
    contiguous range and siblings keep description order."""
    def link(name):
        return Link(name, Inertial(scalar(1.0)))

    joints = [Joint(name, JointType.REVOLUTE, parent, child) for name, parent, child in [
        ("a", "base", "A"), ("b", "base", "B"), ("a1", "A", "A1"), ("b1", "B", "B1"),
        ("a2", "A", "A2"), ("a11", "A1", "A11")]]
    model = build_model("<test>", "tree", [link(n) for n in
                                           ("base", "A", "B", "A1", "B1", "A2", "A11")], joints)
    nm = numeric_model(model)
    assert nm.body_names == ("base", "A", "A1", "A11", "A2", "B", "B1")
    assert list(nm.parent) == [-1, 0, 1, 2, 1, 0, 5]
    assert list(nm.q_index) == [-1, 0, 2, 5, 4, 1, 3]


def test_numeric_model_is_read_only():
    nm = numeric_model(two_link_arm(1, 1, 1, 0.5, 0.5, 0.1, 0.1))
    assert isinstance(nm, NumericModel)
    assert nm.body_names[0] == "base" and nm.parent[0] == -1
    assert list(nm.q_index) == [-1, 0, 1, -1]
    with pytest.raises(ValueError):
        nm.mass[1] = 5.0
    with pytest.raises(AttributeError):
        nm.gravity = np.zeros(3)


# ----------------------------------------------------------------------------------------------
# example-robot-data through eomgen's URDF parser
# ----------------------------------------------------------------------------------------------

ERD_ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
}


@pytest.mark.parametrize("robot", sorted(ERD_ROBOTS))
def test_example_robot_data(robot, erd_robots_dir):
    import eomgen
    from eomgen.errors import UnsupportedFeatureWarning

    path = erd_robots_dir / ERD_ROBOTS[robot]
    with warnings.catch_warnings():
        # Panda's second finger <mimic>s the first: both tools read it as an independent joint
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)
        model = eomgen.load(path, couplings=False)
    nm = numeric_model(model)
    pmodel = pin.buildModelFromUrdf(str(path))
    pmodel.gravity = pin.Motion(nm.gravity.copy(), np.zeros(3))
    ref = PinocchioReference(model, pmodel)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd, qdd = random_state(rng, nm.n)
        assert_close(rnea(nm, q, qd, qdd), ref.rnea(q, qd, qdd))
        assert_close(M_rnea(nm, q), ref.mass_matrix(q))
        frames = ref.frame_poses(q)
        for name, (R, p) in link_poses(nm, q).items():
            if name in frames:
                assert_close(R, frames[name].rotation)
                assert_close(p, frames[name].translation)


@pytest.mark.parametrize("robot", sorted(ERD_ROBOTS))
def test_one_rnea_in_float64_and_mpmath(robot, erd_robots_dir):
    """rnea is one implementation generic over the number type: on the same model in mpmath
    numbers at 50 digits (eomgen.analysis.precision.MPMATH) it gives the float64 result to
    rounding (~1e-14 relative), and the mpmath values really carry more than double
    precision (the float64 run is not what the mpmath run computes)."""
    mpmath = need("mpmath", reason="the mpmath number type needs mpmath")
    import eomgen
    from eomgen.analysis.precision import MPMATH
    from eomgen.errors import UnsupportedFeatureWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)
        model = eomgen.load(erd_robots_dir / ERD_ROBOTS[robot], couplings=False)
    nm = numeric_model(model)
    mm = numeric_model(model, numbers=MPMATH)
    assert mm.mass.dtype == object and isinstance(mm.mass[1], mpmath.mpf)
    rng = np.random.default_rng(3)
    q, qd, qdd = random_state(rng, nm.n)
    with mpmath.workdps(50):
        tau_mp = rnea(mm, q, qd, qdd)
        M_mp = M_rnea(mm, q)
        assert all(isinstance(x, mpmath.mpf) for x in tau_mp)
        # the same 50-digit run at 30 digits: the two agree far below double precision
        with mpmath.workdps(30):
            tau_30 = rnea(mm, q, qd, qdd)
        assert max(abs(a - b) for a, b in zip(tau_mp, tau_30)) < mpmath.mpf(10) ** -25
    assert_close(np.array(tau_mp, dtype=float), rnea(nm, q, qd, qdd), rtol=1e-14)
    M_float = M_rnea(nm, q)
    assert_close(np.array(M_mp, dtype=float), M_float, rtol=1e-14)
    assert np.any(np.array(tau_mp, dtype=float) != rnea(nm, q, qd, qdd)) or \
        np.any(np.array(M_mp, dtype=float) != M_float)
