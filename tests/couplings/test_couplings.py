"""Coupled joints (issue 26): URDF <mimic> and linear couplings q_f = K q + c.

References: Pinocchio's mimic joints (the Panda, finger_joint2 <mimic> finger_joint1), the
constrained whole tree (KKT with the coupling as a constraint) and the identities
M_r = Tᵀ M T, τ_r = Tᵀ RNEA(T q + c, T q̇, T q̈) on the uncoupled model by eomgen's float
Newton–Euler recursion, in every code backend.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.codegen.generate import generate
from eomgen.errors import KinematicTreeError, UnsupportedError
from eomgen.model import couple, coupling_map, lock_joints, uncoupled
from eomgen.numeric.newton_euler import M_rnea, numeric_model, rnea
from support import erd_robots_dir, load_module
from support.extras import need

BACKENDS = ("numpy", "fast", "casadi", "jax", "torch")


def relative(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


def numeric_map(model):
    T, c = coupling_map(model)
    return np.array(T.evalf(), float), np.array(c.evalf(), float)[:, 0]


@pytest.fixture(scope="module")
def panda():
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    path = robots / "panda_description/urdf/panda.urdf"
    model = eomgen.load(path)
    functions = eomgen.derive(model, ("M", "C", "g", "tau")).lambdify()
    return path, model, functions


def test_panda_mimic_matches_pinocchio(panda):
    pin = need("pinocchio")
    path, model, f = panda
    assert model.dof == 8 and "panda_finger_joint2" not in model.joint_names
    pmodel = pin.buildModelFromUrdf(str(path), mimic=True)
    data = pmodel.createData()
    assert (pmodel.nq, pmodel.nv) == (8, 8)
    assert [n for n in pmodel.names[1:] if n in model.joint_names] == list(model.joint_names)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = np.append(rng.uniform(-1.5, 1.5, 7), rng.uniform(0, 0.04))
        v, a = rng.normal(size=(2, 8))
        M = pin.crba(pmodel, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        assert relative(f.M(q), M) <= 1e-10
        assert relative(f.C(q, v) @ v + f.g(q), pin.nonLinearEffects(pmodel, data, q, v)) <= 1e-10
        assert relative(f.g(q), pin.computeGeneralizedGravity(pmodel, data, q)) <= 1e-10
        assert relative(f.tau(q, v, a), pin.rnea(pmodel, data, q, v, a)) <= 1e-10


def test_panda_reduced_model_is_the_constrained_whole_tree(panda):
    """q̈ of the 8-coordinate model equals the q̈ of the 9-joint tree with finger2 = finger1
    held by a constraint (KKT), the efforts on the independent joints."""
    _, model, f = panda
    whole = numeric_model(uncoupled(model))
    T, c = numeric_map(model)
    J = np.zeros((1, 9))
    J[0, 7], J[0, 8] = 1.0, -1.0  # q_f1 - q_f2 = 0
    rng = np.random.default_rng(5)
    for _ in range(2):
        q = np.append(rng.uniform(-1.5, 1.5, 7), rng.uniform(0, 0.04))
        v, tau = rng.normal(size=(2, 8))
        qdd = np.linalg.solve(f.M(q), tau - f.C(q, v) @ v - f.g(q))
        Q, V = T @ q + c, T @ v
        assert abs(J @ Q)[0] < 1e-15 and abs(J @ V)[0] < 1e-15
        M = M_rnea(whole, Q)
        h = rnea(whole, Q, V, np.zeros(9))
        effort = np.append(tau, 0.0)  # on the independent joints; T^T effort = tau
        kkt = np.block([[M, -J.T], [J, np.zeros((1, 1))]])
        solution = np.linalg.solve(kkt, np.append(effort - h, 0.0))
        assert relative(solution[:9], T @ qdd) <= 1e-10


@pytest.fixture(scope="module")
def differential():
    """A 3-joint arm whose third joint follows 0.5 q1 - 0.3 q2 + 0.1 (a differential)."""
    arm = eomgen.load(eomgen.example_path("elbow_rrr"))
    return arm, couple(arm, "elbow", {"waist": 0.5, "shoulder": -0.3}, offset=0.1)


def test_differential_in_every_backend(differential, tmp_path_factory):
    arm, model = differential
    assert model.joint_names == ("waist", "shoulder")
    folder = tmp_path_factory.mktemp("differential")
    wanted = [b for b in BACKENDS if b in ("numpy", "fast") or _has(b)]
    paths = generate(model, folder, ",".join(wanted), cache=False)
    whole = numeric_model(arm)
    T, c = numeric_map(model)
    rng = np.random.default_rng(11)
    states = [rng.normal(size=(3, 2)) for _ in range(2)]
    for backend in wanted:
        path = next(p for p in paths if p.name.endswith((f"_{backend}.py",))
                    or (backend == "fast" and p.suffix == ".so"))
        module = load_module(path, path.name.split(".")[0])
        if backend == "casadi":
            module = casadi_functions(module, paths)
        for q, qd, qdd in states:
            Q, V, A = T @ q + c, T @ qd, T @ qdd
            g = rnea(whole, Q, 0 * V, 0 * A)
            M = np.asarray(module.mass_matrix(q))
            tol = 1e-12 if M.dtype == np.float64 else 1e-5  # JAX without x64: float32
            assert relative(M, T.T @ M_rnea(whole, Q) @ T) <= tol, backend
            assert relative(np.asarray(module.gravity_vector(q)), T.T @ g) <= tol, backend
            Cqd = np.asarray(module.coriolis_matrix(q, qd)) @ qd
            assert relative(Cqd, T.T @ (rnea(whole, Q, V, 0 * A) - g)) <= tol, backend
            tau = np.asarray(module.inverse_dynamics(q, qd, qdd))
            assert relative(tau, T.T @ rnea(whole, Q, V, A)) <= tol, backend
            back = np.asarray(module.forward_dynamics(q, qd, tau))
            assert relative(back, qdd) <= (1e-9 if M.dtype == np.float64 else 1e-3), backend


def casadi_functions(module, paths):
    """The CasADi module's functions called like the NumPy module's (parameters at their
    defaults, the NumPy module's PARAMETERS)."""
    numpy_path = next(p for p in paths if p.name.endswith("_numpy.py"))
    defaults = load_module(numpy_path, numpy_path.stem).PARAMETERS

    def wrap(f):
        def call(*vectors):
            extra = [defaults[name] for name in f.name_in()[len(vectors):]]
            out = np.array(f(*vectors, *extra).full())
            return out[:, 0] if out.shape[1] == 1 and f.name() != "mass_matrix" else out
        return call

    return type("CasadiModule", (), {name: staticmethod(wrap(getattr(module, name)))
                                     for name in ("mass_matrix", "coriolis_matrix",
                                                  "gravity_vector", "inverse_dynamics",
                                                  "forward_dynamics")})


def _has(backend: str) -> bool:
    import importlib.util

    return importlib.util.find_spec(backend) is not None


def test_christoffel_C_of_the_reduced_lagrangian(differential):
    """Ṁ_r − 2 C_r is skew (C_r is the reduced Lagrangian's Christoffel C, not just any C
    with the right C q̇), Ṁ_r by a central difference along q̇."""
    _, model = differential
    f = eomgen.derive(model, ("M", "C")).lambdify()
    rng = np.random.default_rng(2)
    q, qd = rng.normal(size=(2, 2))
    h = 1e-6
    Mdot = (f.M(q + h * qd) - f.M(q - h * qd)) / (2 * h)
    N = Mdot - 2 * f.C(q, qd)
    assert np.abs(N + N.T).max() <= 1e-8


def test_jacobians_and_regressor_are_projected(differential):
    """J_r = J T (frame Jacobian) and Y_r π = τ_r."""
    arm, model = differential
    scene = eomgen.load_scene("s.yaml", text="version: 1\nframes: [link3]\n")
    reduced = eomgen.apply_scene(model, scene)[0]
    assert reduced.couplings == model.couplings
    full = eomgen.apply_scene(arm, scene)[0]
    ours = eomgen.derive(reduced, ("J_f", "Y", "pi", "tau")).lambdify()
    theirs = eomgen.derive(full, ("J_f",)).lambdify()
    T, c = numeric_map(model)
    q, qd, qdd = np.random.default_rng(4).normal(size=(3, 2))
    assert relative(ours.module.frame_jacobians(q),
                    theirs.module.frame_jacobians(T @ q + c) @ T) <= 1e-12
    Y, pi = ours.module.regressor(q, qd, qdd), ours.module.inertial_parameters()
    assert Y.shape == (2, len(ours.module.PARAMETER_NAMES)) == (2, 30)  # three bodies
    assert relative(Y @ pi, ours.tau(q, qd, qdd)) <= 1e-12


def test_outputs_not_projected_are_refused(differential):
    _, model = differential
    with pytest.raises(UnsupportedError, match="qdd_aba not derived for a model with coupled"):
        eomgen.derive(model, ("M", "qdd_aba"))


def test_bad_couplings_are_one_line_errors(differential):
    arm, model = differential
    cases = [
        (lambda: couple(arm, "elbow", "ghost"), "joint 'ghost' is not defined"),
        (lambda: couple(arm, "elbow", "elbow"), "coupling cycle 'elbow' -> 'elbow'"),
        (lambda: couple(couple(arm, "elbow", "shoulder"), "shoulder", "elbow"),
         "coupling cycle 'elbow' -> 'shoulder' -> 'elbow'"),
        (lambda: couple(couple(arm, "elbow", "shoulder"), "waist", "elbow"),
         "leader 'elbow' is itself a follower"),
        (lambda: couple(model, "elbow", "waist"), "joint 'elbow' already follows"),
        (lambda: couple(lock_joints(arm, {"waist": 0}), "elbow", "waist"),
         "joint 'waist' is fixed: only movable joints can be coupled"),
    ]
    for make, message in cases:
        with pytest.raises(KinematicTreeError) as caught:
            make()
        text = str(caught.value)
        assert message in text and text.startswith(arm.source) and "\n" not in text


def test_locking_a_leader_locks_its_follower(differential):
    arm, model = differential
    locked = lock_joints(model, {"waist": 0.4})
    assert locked.joint_names == ("shoulder",)
    assert [(c.follower, c.leaders) for c in locked.couplings] == [
        ("elbow", (("shoulder", model.couplings[0].leaders[1][1]),))]
    assert abs(float(locked.couplings[0].offset) - 0.3) < 1e-12  # 0.5 * 0.4 + 0.1
    both = lock_joints(model, {"waist": 0.4, "shoulder": 0.0})
    assert both.dof == 0 and not both.couplings
    with pytest.raises(KinematicTreeError, match="cannot lock a coupled joint while its leader"):
        lock_joints(model, {"elbow": 0.0})
    with pytest.raises(KinematicTreeError, match="locked at 1"):
        lock_joints(model, {"waist": 0, "shoulder": 0, "elbow": 1})


def test_scene_couplings_key(tmp_path):
    """A scene's differential: the same model as couple(); errors name the scene entry."""
    arm = eomgen.load(eomgen.example_path("elbow_rrr"))
    scene = eomgen.load_scene("s.yaml", text=(
        "version: 1\ncouplings:\n  - {joint: elbow, to: {waist: 0.5, shoulder: -0.3}, "
        "offset: 0.1}\n"))
    reduced = eomgen.apply_scene(arm, scene)[0]
    expected = couple(arm, "elbow", {"waist": 0.5, "shoulder": -0.3}, offset=0.1)
    assert reduced.joint_names == ("waist", "shoulder")
    assert reduced.couplings == expected.couplings
    T, c = numeric_map(reduced)
    assert np.allclose(T, [[1, 0], [0, 1], [0.5, -0.3]]) and np.allclose(c, [0, 0, 0.1])
    bad = {
        "couplings:\n  - {joint: elbow, to: ghost}\n":
            "s.yaml: couplings[0] 'elbow': joint 'ghost' is not defined",
        "locked: {waist: 0.2}\ncouplings:\n  - {joint: elbow, to: waist, ratio: 2}\n":
            "s.yaml: couplings[0] 'elbow': joint 'waist' is locked by the scene: a locked "
            "joint cannot be coupled",
        "couplings:\n  - {joint: elbow, to: shoulder}\n  - {joint: shoulder, to: elbow}\n":
            "s.yaml: couplings[0] 'elbow': coupling cycle 'elbow' -> 'shoulder' -> 'elbow'",
        "couplings:\n  - {joint: elbow, to: shoulder, gain: 2}\n": "s.yaml: couplings[0]: unknown key 'gain'",
    }
    for text, message in bad.items():
        with pytest.raises(eomgen.errors.SceneError) as caught:
            eomgen.apply_scene(arm, eomgen.load_scene("s.yaml", text="version: 1\n" + text))
        assert str(caught.value).startswith(message), str(caught.value)


def test_a_follower_outside_the_moving_part_goes_with_its_leader():
    arm = couple(eomgen.load(eomgen.example_path("elbow_rrr")), "elbow", "waist", ratio=2,
                 offset=0.1)
    locked = eomgen.apply_scene(arm, eomgen.load_scene(
        "s.yaml", text="version: 1\nlocked: {waist: 0.4}\ntips: [link2]\n"))
    assert locked.model.joint_names == ("shoulder",) and not locked.model.couplings
    assert [(j.name, round(j.position, 12), j.listed) for j in locked.report.locked] == [
        ("waist", 0.4, True), ("elbow", 0.9, False)]  # 2 * 0.4 + 0.1, not 0
    moving = eomgen.apply_scene(arm, eomgen.load_scene("s.yaml", text="version: 1\n"
                                                       "tips: [link2]\n"))
    assert moving.model.joint_names == ("waist", "shoulder")
    assert moving.model.couplings == arm.couplings  # elbow still follows the waist


def test_slotine_li_regressor_under_couplings(differential):
    """Y_SL π = M_r q̈_r + C_r(q, q̇) q̇_r + g_r with the reduced M, Christoffel C and g."""
    _, model = differential
    f = eomgen.derive(model, ("M", "C", "g", "Y_SL", "pi")).lambdify()
    q, qd, qd_r, qdd_r = np.random.default_rng(8).normal(size=(4, 2))
    Y = f.module.slotine_li_regressor(q, qd, qd_r, qdd_r)
    expected = f.M(q) @ qdd_r + f.C(q, qd) @ qd_r + f.g(q)
    assert relative(Y @ f.module.inertial_parameters(), expected) <= 1e-12
