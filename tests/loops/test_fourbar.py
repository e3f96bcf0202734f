"""Loop closures on the planar four-bar (examples/robots/fourbar.yaml, closed by
examples/loops/fourbar_loop.yaml), against references that share no code with eomgen:

* the closed form of its header: the crank angle θ as the one coordinate, the rocker and
  coupler angles by circle intersection, the Euler–Lagrange equation of the reduced Lagrangian
  (SymPy, one variable) for θ̈ and so q̈;
* the Newton–Euler balance of each rod as a free body (9 equations, 8 pin and loop forces:
  solved in least squares, the residual proving q̈ consistent) for the loop force λ;
* finite differences of Φ for J_l and of J_l q̇ along the motion for J̇_l q̇.

Also: the scene's bad input (a loop on one rigid body), Newton closure and its error.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.errors import SceneError
from eomgen.numeric.loops import AssemblyError, LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT

ROBOT = ROOT / "examples/robots/fourbar.yaml"
SCENE = ROOT / "examples/loops/fourbar_loop.yaml"
a, b, c, d = 0.2, 0.6, 0.5, 0.6
m = (1.0, 2.0, 1.5)
lengths = (a, b, c)
G = 9.81


@pytest.fixture(scope="module")
def fourbar():
    model = apply_scene(eomgen.load(ROBOT), load_scene(SCENE)).model
    return LoopDynamics(model)


@pytest.fixture(scope="module")
def closed_form():
    """Functions of θ: q(θ), s = dq/dθ, s' = d²q/dθ², m(θ), m'(θ), V'(θ) (module docstring)."""
    t = sp.Symbol("theta")
    A = sp.Matrix([a * sp.cos(t), a * sp.sin(t)])
    D = sp.Matrix([d, 0])
    e = D - A
    E = e.dot(e)
    phi = sp.atan2(e[1], e[0]) + sp.pi - sp.acos((E + c ** 2 - b ** 2) / (2 * c * sp.sqrt(E)))
    P = D + c * sp.Matrix([sp.cos(phi), sp.sin(phi)])
    beta = sp.atan2(P[1] - A[1], P[0] - A[0])
    q = sp.Matrix([t, beta - t, phi])
    u = lambda x: sp.Matrix([sp.cos(x), sp.sin(x)])  # noqa: E731
    coms = [a / 2 * u(t), A + b / 2 * u(beta), D + c / 2 * u(phi)]
    angles = [t, beta, phi]
    mass = sum(mi * dc.diff(t).dot(dc.diff(t)) + mi * li ** 2 / 12 * ang.diff(t) ** 2
               for mi, li, dc, ang in zip(m, lengths, coms, angles))
    V = sum(mi * G * com[1] for mi, com in zip(m, coms))
    s = q.diff(t)
    fn = lambda expr: sp.lambdify(t, expr, "numpy")  # noqa: E731
    return {"q": fn(q), "s": fn(s), "ds": fn(s.diff(t)), "m": fn(mass), "dm": fn(mass.diff(t)),
            "dV": fn(V.diff(t))}


def _flat(x):
    return np.asarray(x, dtype=float).reshape(-1)


STATES = [(0.3, 1.5, (0.7, -0.2, 0.3)), (2.2, -0.8, (0.0, 0.0, 0.0)), (4.0, 3.0, (1.5, 0, 0))]


@pytest.mark.parametrize("theta, rate, tau", STATES)
def test_fourbar_forward_dynamics_against_closed_form(fourbar, closed_form, theta, rate, tau):
    cf = closed_form
    q = _flat(cf["q"](theta))
    s, ds = _flat(cf["s"](theta)), _flat(cf["ds"](theta))
    qd = s * rate
    tau = np.asarray(tau, dtype=float)
    theta_dd = (tau @ s - 0.5 * float(cf["dm"](theta)) * rate ** 2 - float(cf["dV"](theta))) \
        / float(cf["m"](theta))
    expected = s * theta_dd + ds * rate ** 2
    assert np.abs(fourbar.loop_constraint(q)).max() < 1e-12
    qdd, lam = fourbar.constrained_forward_dynamics(q, qd, tau)
    assert np.abs(qdd - expected).max() <= 1e-9 * max(1.0, np.abs(expected).max())
    # the loop force from the free-body balance of each rod (Newton-Euler, planar)
    forces, residual = _free_body_forces(q, qd, qdd, tau)
    assert residual <= 1e-9 * max(1.0, np.abs(forces).max())
    assert np.abs(lam - forces[4:6]).max() <= 1e-9 * max(1.0, np.abs(lam).max())
    # the parallel inverse dynamics (crank actuated) gives back the crank torque and λ
    tau_a, lam_id = fourbar.parallel_inverse_dynamics(q, qd, qdd) if not tau[1:].any() else \
        (None, None)
    if tau_a is not None:
        assert abs(tau_a[0] - tau[0]) <= 1e-9 * max(1.0, abs(tau[0]))
        assert np.abs(lam_id - lam).max() <= 1e-9 * max(1.0, np.abs(lam).max())


def _cross(r, f) -> float:
    return r[0] * f[1] - r[1] * f[0]


def _free_body_forces(q, qd, qdd, tau):
    """Unknowns (f_O, f_A, λ, f_D) of the three rods' Newton–Euler equations (9 rows): f_O
    ground on crank at O, f_A crank on coupler at A, λ on the coupler at its tip P (−λ on the
    rocker), f_D ground on rocker at D. Returns (forces, residual of the least squares)."""
    u = lambda x: np.array([np.cos(x), np.sin(x)])  # noqa: E731
    up = lambda x: np.array([-np.sin(x), np.cos(x)])  # noqa: E731
    ang = [q[0], q[0] + q[1], q[2]]
    w = [qd[0], qd[0] + qd[1], qd[2]]
    al = [qdd[0], qdd[0] + qdd[1], qdd[2]]
    O, D = np.zeros(2), np.array([d, 0.0])
    A = a * u(ang[0])
    aA = a * (al[0] * up(ang[0]) - w[0] ** 2 * u(ang[0]))
    P = D + c * u(ang[2])
    pivots, acc_pivot = [O, A, D], [np.zeros(2), aA, np.zeros(2)]
    coms = [p + l / 2 * u(x) for p, l, x in zip(pivots, lengths, ang)]
    acc = [ap + l / 2 * (alpha * up(x) - wi ** 2 * u(x))
           for ap, l, x, alpha, wi in zip(acc_pivot, lengths, ang, al, w)]
    rows, rhs = [], []
    # columns: f_O (0, 1), f_A (2, 3), λ (4, 5), f_D (6, 7)
    body_forces = [[(0, 1.0, O), (2, -1.0, A)], [(2, 1.0, A), (4, 1.0, P)],
                   [(6, 1.0, D), (4, -1.0, P)]]
    torques = [tau[0] - tau[1], tau[1], tau[2]]
    for k in range(3):
        for axis in range(2):
            row = np.zeros(8)
            for col, sign, _ in body_forces[k]:
                row[col + axis] = sign
            rows.append(row)
            rhs.append(m[k] * acc[k][axis] + (m[k] * G if axis == 1 else 0.0))
        row = np.zeros(8)
        for col, sign, point in body_forces[k]:
            r = point - coms[k]
            row[col], row[col + 1] = -sign * r[1], sign * r[0]  # (r × f)_z
        rows.append(row)
        rhs.append(m[k] * lengths[k] ** 2 / 12 * al[k] - torques[k])
    K, y = np.array(rows), np.array(rhs)
    x = np.linalg.lstsq(K, y, rcond=None)[0]
    return x, float(np.abs(K @ x - y).max())


def test_loop_jacobian_and_bias_by_finite_differences(fourbar):
    rng = np.random.default_rng(3)
    q = fourbar.assemble([0.9, 1.0, 1.8])
    for _ in range(2):
        x = q + rng.uniform(-0.3, 0.3, 3)  # also away from closure: the rows are exact
        qd = rng.uniform(-1, 1, 3)
        h = 1e-6
        J = fourbar.loop_jacobian(x)
        fd = np.array([(fourbar.loop_constraint(x + h * e) - fourbar.loop_constraint(x - h * e))
                       / (2 * h) for e in np.eye(3)]).T
        assert np.abs(J - fd).max() < 1e-8
        Jdot_qd = (fourbar.loop_jacobian(x + h * qd) - fourbar.loop_jacobian(x - h * qd)) \
            / (2 * h) @ qd
        assert np.abs(fourbar.loop_bias(x, qd) - Jdot_qd).max() < 1e-7


def test_assemble_closes_and_refuses_out_of_reach(fourbar):
    q = fourbar.assemble([1.0, 0.0, 0.0])
    assert q[0] == 1.0 and np.abs(fourbar.loop_constraint(q)).max() <= 1e-12
    far = LoopDynamics(apply_scene(eomgen.load(ROBOT), load_scene("far.yaml", text=(
        SCENE.read_text().replace("xyz: [0.6, 0, 0]", "xyz: [2.5, 0, 0]")))).model)
    with pytest.raises(AssemblyError, match=r"do not assemble.*\|Phi\| = "):
        far.assemble([0.3, 1.0, 2.0])


def test_a_loop_on_one_rigid_body_is_refused():
    text = SCENE.read_text().replace("link: rocker", "link: coupler")
    with pytest.raises(SceneError, match=r"loops\[0\] 'pin'.*same rigid body 'coupler'"):
        apply_scene(eomgen.load(ROBOT), load_scene("same.yaml", text=text))
    with pytest.raises(SceneError, match=r"only a hinge loop has an axis"):
        load_scene("axis.yaml", text=SCENE.read_text().replace("plane:", "axis:"))
    with pytest.raises(SceneError, match=r"actuated\[0\].*did you mean 'crank_joint'"):
        apply_scene(eomgen.load(ROBOT), load_scene("act.yaml", text=SCENE.read_text().replace(
            "actuated: [crank_joint]", "actuated: [crank_jiont]")))


def test_documented_loop_errors_are_what_eomgen_prints():
    text = (ROOT / "docs/scenes.md").read_text(encoding="utf-8")
    documented = [line[len("eomgen: error: "):] for line in text.splitlines()
                  if line.startswith("eomgen: error: fourbar_scene.yaml")]
    scene = SCENE.read_text()
    printed = []
    for bad in (scene.replace("link: rocker", "link: coupler"),
                scene.replace("actuated: [crank_joint]", "actuated: [crank_jiont]")):
        with pytest.raises(SceneError) as caught:
            apply_scene(eomgen.load(ROBOT), load_scene("fourbar_scene.yaml", text=bad))
        printed.append(str(caught.value))
    assert printed == documented


def test_a_loop_may_end_on_the_fixed_root():
    """Frame a on the root link (the world): the crank and coupler alone, their tip held at a
    point of the ground, close by Newton to the two-link arm's inverse kinematics."""
    text = SCENE.read_text().replace("a: {link: rocker, xyz: [0.5, 0, 0]}",
                                     "a: {link: ground, xyz: [0.6, 0.5, 0]}").replace(
        "actuated: [crank_joint]", "actuated: [rocker_joint]")
    dyn = LoopDynamics(apply_scene(eomgen.load(ROBOT), load_scene("root.yaml", text=text)).model)
    q = dyn.assemble([0.5, 1.0, 2.0])
    tip = a * np.array([np.cos(q[0]), np.sin(q[0])]) + 0.6 * np.array(
        [np.cos(q[0] + q[1]), np.sin(q[0] + q[1])])
    assert np.allclose(tip, [0.6, 0.5], atol=1e-12) and q[2] == 2.0
    J = dyn.loop_jacobian(q)
    assert np.allclose(J[:, 2], 0) and np.allclose(J[:, 1], 0.6 * np.array(
        [-np.sin(q[0] + q[1]), np.cos(q[0] + q[1])]))
