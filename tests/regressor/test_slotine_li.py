"""The generated Slotine–Li regressor (issue 28: ``slotine_li_regressor``,
``slotine_li_base_regressor``) against independent computations: Pinocchio's ``crba``,
``computeCoriolisMatrix`` and ``computeGeneralizedGravity`` (M q̈_r + C(q, q̇) q̇_r + g, the
Christoffel C) on random chains and trees and the UR5, the generated joint torque regressor
(Y_SL(q, q̇, q̇, q̈) = Y(q, q̇, q̈)) and the base parameters (Y_SL_base β = Y_SL π), in every
backend on the planar arm with drives (armature and viscous terms written out by hand)."""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from support import random_states, rng_of
from support.generated import BACKENDS, generated
from support.reference import pin_q_order, random_robot, to_pinocchio
from support.robots import ur5
from support.extras import need

pin = need("pinocchio")

FUNCTIONS = ("slotine_li_regressor", "slotine_li_base_regressor", "regressor",
             "inertial_parameters", "base_parameters")

#: Drives of the planar arm: armature a q̈_r + viscous d q̇_r + Coulomb f sign q̇ per joint.
DRIVES_SCENE = """version: 1
actuators:
  joint1: {armature: 0.3, damping: 0.5, friction: 1.0}
  joint2: {armature: 0.1, damping: 0.2, friction: 0.7}
symbolic: [m2]
"""
ARMATURE, DAMPING, COULOMB = np.array([0.3, 0.1]), np.array([0.5, 0.2]), np.array([1.0, 0.7])


def reference_states(n: int, count: int, seed: int):
    """``count`` tuples (q, q̇, q̇_r, q̈_r) of random (n,) vectors."""
    rng = rng_of(seed)
    return [tuple(rng.uniform(-2, 2, n) for _ in range(4)) for _ in range(count)]


def pinocchio_reference(model):
    """``f(q, qd, qd_r, qdd_r) = M qdd_r + C(q, qd) qd_r + g`` from Pinocchio (our joint order)."""
    pm = to_pinocchio(model)
    data = pm.createData()
    perm = pin_q_order(model, pm)

    def f(q, qd, qd_r, qdd_r):
        x, v = q[perm], qd[perm]
        M = np.array(pin.crba(pm, data, x))
        M = np.triu(M) + np.triu(M, 1).T  # crba fills the upper triangle
        C = np.array(pin.computeCoriolisMatrix(pm, data, x, v))
        g = np.array(pin.computeGeneralizedGravity(pm, data, x))
        out = np.empty(len(q))
        out[perm] = M @ qdd_r[perm] + C @ qd_r[perm] + g
        return out

    return f


def check_against_pinocchio(model, call, count=4, seed=3, base=True):
    reference = pinocchio_reference(model)
    pi = call("inertial_parameters")
    beta = call("base_parameters") if base else None
    for q, qd, qd_r, qdd_r in reference_states(model.dof, count, seed):
        Y_SL = call("slotine_li_regressor", q, qd, qd_r, qdd_r)
        expected = reference(q, qd, qd_r, qdd_r)
        scale = max(1.0, np.abs(expected).max())
        np.testing.assert_allclose(Y_SL @ pi, expected, rtol=0, atol=1e-10 * scale)
        # with the robot's own velocity and acceleration it is the joint torque regressor
        Y = call("regressor", q, qd, qdd_r)
        np.testing.assert_allclose(call("slotine_li_regressor", q, qd, qd, qdd_r), Y, rtol=0,
                                   atol=1e-12 * max(1.0, np.abs(Y).max()))
        if base:
            np.testing.assert_allclose(call("slotine_li_base_regressor", q, qd, qd_r, qdd_r)
                                       @ beta, Y_SL @ pi, rtol=0, atol=1e-10 * scale)


@pytest.mark.parametrize("n, tree, seed", [(3, False, 1), (4, True, 2)])
def test_random_robots_match_pinocchio(tmp_path, n, tree, seed):
    model = random_robot(rng_of(seed), n, tree=tree)
    calls, _ = generated(model, FUNCTIONS[:4] if n > 3 else FUNCTIONS, tmp_path, ("numpy",))
    check_against_pinocchio(model, calls["numpy"], base=n <= 3)


# The realistic arm. (A random 7-joint tree was checked here too, left out for the suite's
# time budget: the 3-joint chain and 4-joint tree above test the same identities at random.)
@pytest.mark.slow
def test_the_ur5_matches_pinocchio(tmp_path):
    model = ur5()
    calls, modules = generated(model, FUNCTIONS, tmp_path, ("numpy",))
    assert len(modules["numpy"]["BASE_PARAMETER_NAMES"]) == 36
    check_against_pinocchio(model, calls["numpy"], count=3)


@pytest.fixture(scope="module")
def driven_arm(tmp_path_factory):
    folder = tmp_path_factory.mktemp("slotine_li_drives")
    (folder / "drives.yaml").write_text(DRIVES_SCENE)
    model = eomgen.apply_scene(eomgen.load(eomgen.example_path("planar_2link")),
                               eomgen.load_scene(folder / "drives.yaml"))[0]
    return (model, *generated(model, FUNCTIONS, folder, BACKENDS))


def test_every_backend_with_drives_and_a_symbolic_mass(driven_arm):
    """The planar arm with armature, viscous and Coulomb drives and m2 kept symbolic: Y_SL π =
    Pinocchio's M q̈_r + C q̇_r + g plus the drive terms, in every backend; Y_SL_base β the same;
    Y_SL(q, q̇, q̇, q̈) = Y(q, q̇, q̈); a batch of states gives a batch of regressors."""
    model, calls, modules = driven_arm
    names = modules["numpy"]["PARAMETER_NAMES"]
    assert tuple(names[20:]) == ("IA1", "IA2", "FV1", "FV2", "FC1", "FC2")
    for m2 in (None, 2.5):
        values = {} if m2 is None else {"m2": m2}
        by_symbol = {p.symbol: v for p in model.parameters for k, v in values.items()
                     if p.symbol.name == k}
        reference = pinocchio_reference(model.with_numeric_parameters(by_symbol))
        assert set(calls) == set(BACKENDS)
        for backend, call in calls.items():
            pi, beta = call("inertial_parameters", **values), call("base_parameters", **values)
            for q, qd, qd_r, qdd_r in reference_states(2, 3, 8):
                Y_SL = call("slotine_li_regressor", q, qd, qd_r, qdd_r, **values)
                drives = ARMATURE * qdd_r + DAMPING * qd_r + COULOMB * np.sign(qd)
                expected = reference(q, qd, qd_r, qdd_r) + drives
                np.testing.assert_allclose(Y_SL @ pi, expected, rtol=1e-12, atol=1e-12,
                                           err_msg=backend)
                Y_base = call("slotine_li_base_regressor", q, qd, qd_r, qdd_r, **values)
                np.testing.assert_allclose(Y_base @ beta, expected, rtol=1e-12, atol=1e-12,
                                           err_msg=backend)
                np.testing.assert_allclose(call("slotine_li_regressor", q, qd, qd, qdd_r,
                                                **values),
                                           call("regressor", q, qd, qdd_r, **values),
                                           rtol=1e-13, atol=1e-13, err_msg=backend)
    q, qd, qd_r, qdd_r = (np.array(x) for x in zip(*reference_states(2, 4, 9)))
    for backend in sorted(set(calls) - {"casadi"}):  # a batch of states; CasADi: one per call
        batch = calls[backend]("slotine_li_base_regressor", q, qd, qd_r, qdd_r)
        single = [calls[backend]("slotine_li_base_regressor", *x)
                  for x in zip(q, qd, qd_r, qdd_r)]
        np.testing.assert_allclose(batch, np.array(single), rtol=1e-14, err_msg=backend)


def test_skew_symmetry_the_adaptive_law_rests_on(driven_arm):
    """sᵀ (Ṁ − 2C) s = 0 with C q̇_r read off the generated Y_SL: C(q, q̇) x = Y_SL(q, q̇, x, 0) π
    − g, and Ṁ by central differences of M(q) = columns Y_SL(q, 0, 0, e_i) π − g (no drives:
    the armature would add a constant)."""
    model, calls, _ = driven_arm
    call = calls["numpy"]
    pi = call("inertial_parameters")
    pi[20:] = 0.0  # drives off
    zero = np.zeros(2)

    def g(q):
        return call("slotine_li_regressor", q, zero, zero, zero) @ pi

    def M(q):
        return np.column_stack([call("slotine_li_regressor", q, zero, zero, e) @ pi - g(q)
                                for e in np.eye(2)])

    def C(q, qd):
        return np.column_stack([call("slotine_li_regressor", q, qd, e, zero) @ pi - g(q)
                                for e in np.eye(2)])

    for q, qd in random_states(4, 2, 3, parts=2):
        h = 1e-6
        Mdot = (M(q + h * qd) - M(q - h * qd)) / (2 * h)
        N = Mdot - 2 * C(q, qd)
        np.testing.assert_allclose(N, -N.T, atol=1e-7)
        assert np.abs(N).max() > 1e-3  # the test sees a non-trivial C
