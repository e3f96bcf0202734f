"""Task-space quantities (issue 27 item 3): operational_space_inertia Λ, operational_space_bias
(μ, p) and dynamically_consistent_inverse J̄ of the NumPy and fast modules against Pinocchio
(computeMinverse, getFrameJacobian(LOCAL_WORLD_ALIGNED), getFrameClassicalAcceleration,
nonLinearEffects, computeGeneralizedGravity) on the UR5 (fixed base) and on a random tree with
a quaternion free flyer (q of NQ, the rest NV); identities (J J̄ = 1, Λ symmetric positive
definite), damping against its formula, and the errors.
"""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.model.floating import add_free_flyer
from support import relative
from support.generated import generated
from support.reference import massive_tree as floating_tree, to_urdf
from support.robots import ur5
from support.extras import need, skip_backend

pin = need("pinocchio", reason="task-space quantities are checked against "
                          "Pinocchio")

FUNCTIONS = ("operational_space_inertia", "operational_space_bias",
             "dynamically_consistent_inverse")
#: The backends whose modules compose the task-space functions.
BACKENDS = ("numpy", "fast", "jax", "torch")




@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    """The UR5: its NumPy module, Pinocchio's model of the same URDF, the frames that move
    (its leaf ``base`` is fixed to the ground)."""
    model = ur5()
    pm = pin.buildModelFromUrdf(str(model.source))
    _, modules = generated(model, FUNCTIONS, tmp_path_factory.mktemp("task_arm"),
                           backends=BACKENDS)
    return modules, pm, ("ee_link", "tool0")


@pytest.fixture(scope="module")
def flyer(tmp_path_factory):
    """A random three-joint tree on a quaternion free flyer, every leaf a frame."""
    fixed = floating_tree(5, 3)
    folder = tmp_path_factory.mktemp("task_flyer")
    (folder / "tree.urdf").write_text(to_urdf(fixed), encoding="utf-8")
    pm = pin.buildModelFromUrdf(str(folder / "tree.urdf"), pin.JointModelFreeFlyer())
    pm.gravity = pin.Motion(np.array([float(x) for x in fixed.gravity]), np.zeros(3))
    _, modules = generated(add_free_flyer(fixed), FUNCTIONS, folder, backends=BACKENDS)
    return modules, pm, tuple(modules["numpy"]["FRAME_NAMES"])


def module_of(modules, backend):
    """``backend``'s module, its task-space functions returning NumPy arrays."""
    if backend not in modules:
        skip_backend(backend, "module")
    namespace = modules[backend]

    def as_numpy(function):
        def call(*args, **keywords):
            out = function(*args, **keywords)
            return tuple(map(np.asarray, out)) if isinstance(out, tuple) else np.asarray(out)
        return call

    return {**namespace, **{name: as_numpy(namespace[name]) for name in FUNCTIONS}}


def states(pm, count, seed):
    """``count`` states (q, v), the same in every run: Pinocchio's own generator (which draws
    the free flyer's unit quaternion) is seeded too, not left to whichever tests ran before
    (they drew the arm into an ill-conditioned Λ, relative error 1e-9, in one run of three)."""
    pin.seed(seed)
    rng = np.random.default_rng(seed)
    return [(pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq)),
             rng.normal(size=pm.nv)) for _ in range(count)]


def pinocchio_task_space(pm, q, v, frame, r):
    """Λ, μ, p, J̄ of ``frame`` from Pinocchio's M⁻¹, frame Jacobian and accelerations (r = 6,
    or 3 for the linear rows)."""
    data = pm.createData()
    Minv = pin.computeMinverse(pm, data, q)
    Minv = np.triu(Minv) + np.triu(Minv, 1).T
    h = pin.nonLinearEffects(pm, data, q, v).copy()
    g = pin.computeGeneralizedGravity(pm, data, q).copy()
    pin.forwardKinematics(pm, data, q, v, np.zeros(pm.nv))
    pin.computeJointJacobians(pm, data, q)
    pin.updateFramePlacements(pm, data)
    fid = pm.getFrameId(frame)
    world = pin.LOCAL_WORLD_ALIGNED
    J = pin.getFrameJacobian(pm, data, fid, world)[:r]
    drift = pin.getFrameClassicalAcceleration(pm, data, fid, world).vector[:r]
    Lam = np.linalg.inv(J @ Minv @ J.T)
    Jbar = Minv @ J.T @ Lam
    return Lam, Jbar.T @ (h - g) - Lam @ drift, Jbar.T @ g, Jbar


# JAX runs op by op here (slow): test_jax_module_equals_numpy holds it to the NumPy module
@pytest.mark.parametrize("backend", [b for b in BACKENDS if b != "jax"])
@pytest.mark.parametrize("robot", ["arm", "flyer"])
@pytest.mark.parametrize("linear", [False, True])
def test_task_space_equals_pinocchio(robot, linear, backend, request):
    modules, pm, frames = request.getfixturevalue(robot)
    module = module_of(modules, backend)
    r = 3 if linear else 6
    qs, vs = zip(*states(pm, 2, seed=11))
    for q, v in zip(qs, vs):
        Lam = module["operational_space_inertia"](q, linear=linear, frames=frames)
        mu, p = module["operational_space_bias"](q, v, linear=linear, frames=frames)
        Jbar = module["dynamically_consistent_inverse"](q, linear=linear, frames=frames)
        assert Lam.shape == (len(frames), r, r) and mu.shape == p.shape == (len(frames), r)
        assert Jbar.shape == (len(frames), pm.nv, r)
        for k, frame in enumerate(frames):
            expected = pinocchio_task_space(pm, q, v, frame, r)
            for got, want in zip((Lam[k], mu[k], p[k], Jbar[k]), expected):
                assert relative(got, want) < 1e-10
    # a batch gives the single states stacked; one frame by name drops the frame axis
    batch = module["operational_space_bias"](np.array(qs), np.array(vs), linear=linear,
                                             frames=frames[-1])
    for k, (q, v) in enumerate(zip(qs, vs)):
        single = module["operational_space_bias"](q, v, linear=linear, frames=frames)
        assert relative(batch[0][k], single[0][-1]) < 1e-13  # JAX: rounding of XLA's order
        assert relative(batch[1][k], single[1][-1]) < 1e-13


def test_jax_module_equals_numpy(flyer):
    """The JAX module's functions (one batch call each) equal the NumPy module's, which the
    test above holds to Pinocchio."""
    modules, pm, frames = flyer
    jax_module, numpy_module = module_of(modules, "jax"), module_of(modules, "numpy")
    q, v = (np.array(x) for x in zip(*states(pm, 2, seed=17)))
    for linear in (False, True):
        for name in FUNCTIONS:
            inputs = (q, v) if name == "operational_space_bias" else (q,)
            got = jax_module[name](*inputs, linear=linear, frames=frames[::-1], damping=1e-9)
            want = numpy_module[name](*inputs, linear=linear, frames=frames[::-1], damping=1e-9)
            for a, b in zip(got if isinstance(got, tuple) else (got,),
                            want if isinstance(want, tuple) else (want,)):
                assert a.shape == b.shape and relative(a, b) < 1e-12


@pytest.mark.parametrize("backend", BACKENDS)
def test_identities_and_damping(flyer, backend):
    """Λ symmetric positive definite, J J̄ = 1; with damping, Λ = (J M⁻¹ Jᵀ + d 1)⁻¹ and
    J̄ = M⁻¹ Jᵀ Λ exactly as the formula (Pinocchio's M⁻¹ and J)."""
    modules, pm, frames = flyer
    module = module_of(modules, backend)
    data = pm.createData()
    for q, _ in states(pm, 2, seed=13):
        Lam = module["operational_space_inertia"](q)
        Jbar = module["dynamically_consistent_inverse"](q)
        Minv = pin.computeMinverse(pm, data, q)
        Minv = np.triu(Minv) + np.triu(Minv, 1).T
        pin.computeJointJacobians(pm, data, q)
        pin.updateFramePlacements(pm, data)
        damped = module["operational_space_inertia"](q, damping=0.1)
        damped_inverse = module["dynamically_consistent_inverse"](q, damping=0.1)
        for k, frame in enumerate(frames):
            J = pin.getFrameJacobian(pm, data, pm.getFrameId(frame), pin.LOCAL_WORLD_ALIGNED)
            assert np.array_equal(Lam[k], Lam[k].T)
            assert np.linalg.eigvalsh(Lam[k]).min() > 0
            assert np.abs(J @ Jbar[k] - np.eye(6)).max() < 1e-10
            expected = np.linalg.inv(J @ Minv @ J.T + 0.1 * np.eye(6))
            assert relative(damped[k], expected) < 1e-10
            assert relative(damped_inverse[k], Minv @ J.T @ expected) < 1e-10


@pytest.mark.parametrize("backend", BACKENDS)
def test_singular_frames_are_refused_unless_damped(arm, backend):
    """The UR5's leaf ``base`` does not move: J M⁻¹ Jᵀ = 0, a LinAlgError naming it (and the
    state of a batch), finite with damping; the stretched arm (q = 0) is singular at tool0."""
    modules, pm, _ = arm
    module = module_of(modules, backend)
    q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
    if backend == "jax":  # pure under jax.jit: nothing raises on values, the results are NaN
        assert not np.all(np.isfinite(module["operational_space_inertia"](q, frames="base")))
        assert np.all(np.isfinite(module["operational_space_inertia"](q, frames=[0, 2])))
        return
    error = np.linalg.LinAlgError
    if backend == "torch":
        import torch  # the PyTorch module raises torch's LinAlgError
        error = torch.linalg.LinAlgError
    with pytest.raises(error, match="frame 'base' .* is singular \\("):
        module["operational_space_inertia"](q)
    assert np.all(np.isfinite(module["operational_space_bias"](q, q, damping=1e-6)[0]))
    with pytest.raises(error, match="frame 'tool0' \\(6x6\\) is singular at "
                       "state 1 \\(.*use damping > 0"):
        module["dynamically_consistent_inverse"](np.array([q, np.zeros(6)]), frames="tool0")
    with pytest.raises(ValueError, match="unknown frame 'hand'"):
        module["operational_space_inertia"](q, frames="hand")
    with pytest.raises(ValueError, match="damping must be a finite number >= 0"):
        module["operational_space_inertia"](q, damping=-1.0)
