"""Derivatives of the contact-constrained forward dynamics (issue 25):
``constrained_forward_dynamics_derivatives`` (every backend) and the printed KKT partials
``constrained_dynamics_partials`` (every backend).

References: Pinocchio's ``constraintDynamics`` and ``computeConstraintDynamicsDerivatives``
with a ``CONTACT_3D`` ``RigidConstraintModel`` in ``LOCAL_WORLD_ALIGNED`` axes at each contact
frame (its λ is the force on the robot, as eomgen's F_c), on models Pinocchio reads from the
same URDF with its own reader: a spatial four-joint arm holding its foot, the same leg on a
quaternion free flyer, and (slow) the Panda holding its hand and the solo12 on its four feet;
central differences of the generated ``constrained_forward_dynamics`` (along eomgen's
``integrate`` for the free flyer); every backend's partials against the NumPy module's.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import erd_robots_or_skip
from support.generated import BACKENDS, generated
from support.held import (constrained_central_differences, held_model,
                          pinocchio_constrained_derivatives)
from support.robots import SOLO
from support.extras import need

pin = need("pinocchio", reason="checked against Pinocchio's derivatives")

DERIVATIVES = "constrained_forward_dynamics_derivatives"
PARTIALS = "constrained_dynamics_partials"
AXES = ("0 0 1", "0 1 0", "1 0 0", "0 0.6 0.8")


def _link(name, mass, com, inertia):
    xx, yy, zz, xy, xz, yz = inertia
    return (f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/>'
            f'<inertia ixx="{xx}" iyy="{yy}" izz="{zz}" ixy="{xy}" ixz="{xz}" iyz="{yz}"/>'
            "</inertial></link>")


def _joint(name, parent, child, xyz, rpy, axis=None):
    kind, body = ("fixed", "") if axis is None else (
        "revolute", f'<axis xyz="{axis}"/><limit effort="1" velocity="1" lower="-3" upper="3"/>')
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/>{body}</joint>')


def leg(joints: int) -> str:
    """A trunk and a chain of ``joints`` revolute joints about assorted axes ending in a
    massless ``foot``; the first joint at the trunk's origin (so that the reduced model's world
    is the URDF's)."""
    parts = [_link("trunk", 3.0, "0.02 -0.01 0.03", (0.1, 0.12, 0.08, 0.01, -0.005, 0.002))]
    parent = "trunk"
    for k in range(joints):
        parts.append(_link(f"l{k}", 1.0 - 0.1 * k, "0.1 0.02 -0.05",
                           (0.01, 0.012, 0.008, 0.001, 0.0, -0.001)))
        parts.append(_joint(f"j{k}", parent, f"l{k}", "0.1 0.05 -0.2" if k else "0 0 0",
                            "0.1 -0.2 0.3" if k else "0 0 0", AXES[k]))
        parent = f"l{k}"
    parts += ['<link name="foot"/>', _joint("ankle", parent, "foot", "0.05 0 -0.3", "0 0 0")]
    return '<robot name="leg">' + "".join(parts) + "</robot>"


def held(path, feet, floating: bool, functions, folder, backends=("numpy",)):
    """(eomgen model, (calls, generated modules), Pinocchio model, constraint models) of the
    URDF at ``path`` with ``feet`` held (and a quaternion free flyer when ``floating``)."""
    model, pm, constraints = held_model(path, feet, floating)
    return model, generated(model, functions, folder, backends=backends), pm, constraints


@pytest.fixture(scope="module", params=["fixed", "floating"])
def case(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp(request.param)
    floating = request.param == "floating"
    path = folder / "leg.urdf"
    path.write_text(leg(1 if floating else 4), encoding="utf-8")
    return held(path, ["foot"], floating, [DERIVATIVES], folder)


def states(pm, count, seed):
    """``count`` states (q, v, τ) of Pinocchio's model ``pm``, the same for a seed whatever ran
    before (``randomConfiguration`` draws from Pinocchio's global generator, seeded here)."""
    rng = np.random.default_rng(seed)
    pin.seed(seed)
    for _ in range(count):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


def check_against_pinocchio(m, pm, constraints, count=2, seed=0, tol=1e-8):
    for q, v, tau in states(pm, count, seed):
        (ddq, lam), refs = pinocchio_constrained_derivatives(pm, constraints, q, v, tau)
        qdd, F = m["constrained_forward_dynamics"](q, v, tau)
        np.testing.assert_allclose(qdd, ddq, rtol=tol, atol=tol)
        np.testing.assert_allclose(F, lam, rtol=tol, atol=tol)
        names = ("dqdd_dq", "dqdd_dqd", "dqdd_dtau", "dF_dq", "dF_dqd", "dF_dtau")
        for name, got, ref in zip(names, m[DERIVATIVES](q, v, tau), refs):
            assert got.shape == ref.shape, name
            scale = max(1.0, np.abs(ref).max())
            np.testing.assert_allclose(got / scale, ref / scale, rtol=0, atol=tol, err_msg=name)


def test_constrained_derivatives_equal_pinocchios(case):
    _, (_, modules), pm, constraints = case
    check_against_pinocchio(modules["numpy"], pm, constraints)


def test_constrained_derivatives_are_central_differences(case):
    model, (_, modules), pm, _ = case
    m, h = modules["numpy"], 1e-6
    cfd = m["constrained_forward_dynamics"]
    for q, v, tau in states(pm, 1, seed=1):
        exact = m[DERIVATIVES](q, v, tau)
        for got, fd in zip(exact, constrained_central_differences(model, cfd, q, v, tau, h)):
            np.testing.assert_allclose(got, fd, rtol=1e-6, atol=1e-6)


@pytest.mark.slow  # a C compile and three array libraries (~20 s)
def test_every_backend_gives_the_numpy_modules_partials_and_derivatives(tmp_path_factory):
    folder = tmp_path_factory.mktemp("partials")
    path = folder / "leg.urdf"
    path.write_text(leg(1), encoding="utf-8")
    model, (calls, modules), pm, _ = held(path, ["foot"], True, [PARTIALS, DERIVATIVES], folder,
                                          BACKENDS)
    rng = np.random.default_rng(5)
    for q, v, a in states(pm, 1, seed=5):
        F = rng.normal(size=3)
        expected = calls["numpy"](PARTIALS, q, v, a, F)
        assert expected.shape == (model.dof + 3, 2 * model.dof)
        for backend, call in calls.items():
            np.testing.assert_allclose(call(PARTIALS, q, v, a, F).reshape(expected.shape),
                                       expected, rtol=1e-11, atol=1e-11, err_msg=backend)
        # the composed derivatives: every backend (CasADi's Function called by name)
        expected = modules["numpy"][DERIVATIVES](q, v, a)
        composing = [b for b in ("casadi", "fast", "jax", "torch") if b in modules]
        for backend in composing:
            f = modules[backend][DERIVATIVES]
            got = (f(q, v, a) if backend != "casadi" else
                   [f.call({"q": q, "qd": v, "tau": a})[name] for name in f.name_out()])
            for k, (x, y) in enumerate(zip(got, expected)):
                np.testing.assert_allclose(np.asarray(x), y, rtol=1e-10, atol=1e-10,
                                           err_msg=f"{backend} result {k}")
        if "fast" in modules:  # a batch, and the solve's errors, in C
            Q, V, U = (np.stack([x, x]) for x in (q, v, a))
            for x, y in zip(modules["fast"][DERIVATIVES](Q, V, U), expected):
                np.testing.assert_allclose(x, np.stack([y, y]), rtol=1e-10, atol=1e-10)
            with pytest.raises(FloatingPointError, match=f"{DERIVATIVES}: .* not finite at "
                               "state 1"):
                modules["fast"][DERIVATIVES](Q, V, U * np.array([[1.0], [np.nan]]))


@pytest.mark.slow  # the Panda's derivation (~1 min)
def test_the_panda_holding_its_hand(tmp_path_factory):
    path = erd_robots_or_skip() / "panda_description" / "urdf" / "panda.urdf"
    folder = tmp_path_factory.mktemp("panda")
    scene = ("version: 1\nlocked: {panda_finger_joint1: 0, panda_finger_joint2: 0}\n"
             "contacts:\n  - {frame: panda_hand}\n")
    model = apply_scene(eomgen.load(path), load_scene("s.yaml", text=scene)).model
    full = pin.buildModelFromUrdf(str(path))
    pm = pin.buildReducedModel(full, [full.getJointId(n) for n in full.names
                                      if "finger" in n], pin.neutral(full))
    assert list(pm.names[1:]) == list(model.joint_names)
    frame = pm.frames[pm.getFrameId("panda_hand")]
    constraints = pin.StdVec_RigidConstraintModel()
    constraints.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, pm,
                                                frame.parentJoint, frame.placement,
                                                pin.LOCAL_WORLD_ALIGNED))
    _, modules = generated(model, [DERIVATIVES], folder, backends=("numpy",))
    check_against_pinocchio(modules["numpy"], pm, constraints, count=1, tol=1e-7)


@pytest.mark.slow  # the solo12's derivation (minutes)
def test_the_solo12_on_its_feet_with_a_quaternion_base(tmp_path_factory):
    path = erd_robots_or_skip() / SOLO
    feet = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    _, (_, modules), pm, constraints = held(path, feet, True, [DERIVATIVES],
                                            tmp_path_factory.mktemp("solo"))
    check_against_pinocchio(modules["numpy"], pm, constraints, count=1, tol=1e-7)
