"""Generated functions that take the contact forces F_c (issue 16): ``contact_inverse_dynamics``
(τ = M q̈ + C q̇ + g − J_cᵀ F_c) and the friction-cone margins, in every code backend, plus the
body ``J̇ q̇`` of the frames.

References: the planar 2-link arm's closed-form tip Jacobian with eomgen.numeric's Newton–Euler
τ; the generated ``constrained_forward_dynamics`` (q̈, F_c) fed back (the contact inverse dynamics
must return the τ it was given); the cone formulas written out in NumPy, and eomgen.numeric.contacts'
numeric cone check; finite differences in time of the generated body Jacobians.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.numeric.contacts import ContactDynamics
from eomgen.errors import GenerationError
from eomgen.numeric import numeric_model, rnea
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support.generated import BACKENDS, generated
from support import run_in_process

# the bundled planar arm (l1 = l2 = 1 in its YAML) with its tip on a wall normal to -x,
# friction 0.5, and a second point contact on link1's frame (rows 4-6, normal +y)
SCENE = """version: 1
robot: planar_2link
contacts:
  - {frame: tip, normal: [-1, 0, 0], mu: 0.5}
  - {name: elbow, frame: link2, normal: [0, 1, 0], mu: 0.8}
"""


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    robot = eomgen.load(eomgen.example_path("planar_2link"))
    model = apply_scene(robot, load_scene("wall.yaml", text=SCENE)).model
    functions = ["contact_inverse_dynamics", "friction_cone_margin", "friction_pyramid_margins",
                 "constrained_forward_dynamics", "frame_body_jacobians",
                 "frame_body_jacobians_dot_qd"]
    calls, modules = generated(model, functions, tmp_path_factory.mktemp("contact_io"))
    return model, calls, modules


def _tip_jacobian(model, q):
    """Closed form: the planar arm's tip moves in the x-y plane, world axes."""
    l1 = l2 = 1.0  # the YAML's values
    s1, s12, c1, c12 = np.sin(q[0]), np.sin(q[0] + q[1]), np.cos(q[0]), np.cos(q[0] + q[1])
    return np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12], [0, 0]])


def test_contact_inverse_dynamics_is_newton_euler_minus_the_contact_forces(arm):
    model, calls, modules = arm
    tip = model.contacts[0].name
    assert tuple(modules["numpy"]["CONTACT_ROWS"]) == (
        f"{tip}.f_x", f"{tip}.f_y", f"{tip}.f_z", "elbow.f_x", "elbow.f_y", "elbow.f_z")
    numeric = numeric_model(model)
    cd = ContactDynamics(model, model.contacts)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, (3, 2))
        F = rng.uniform(-5, 5, 6)
        J_tip = _tip_jacobian(model, q)
        expected = rnea(numeric, q, qd, qdd) - cd.contact_jacobian(q).T @ F
        # the tip's rows are the closed form (the elbow's from eomgen.numeric.contacts)
        np.testing.assert_allclose(cd.contact_jacobian(q)[:3], J_tip, atol=1e-12)
        for backend, call in calls.items():
            got = call("contact_inverse_dynamics", q, qd, qdd, F)
            np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12, err_msg=backend)


def test_constrained_forward_dynamics_round_trips_through_the_contact_inverse(arm):
    """(q̈, F_c) holding the contacts under τ give back τ (one contact only: two point
    contacts over-constrain a 2-joint arm, so this uses a damped KKT solve and compares the
    inverse with the forces it produced)."""
    model, calls, modules = arm
    np_module = modules["numpy"]
    rng = np.random.default_rng(5)
    q, qd, tau = rng.uniform(-1, 1, (3, 4, 2))
    qdd, F = np_module["constrained_forward_dynamics"](q, qd, tau, damping=1e-3)
    assert qdd.shape == (4, 2) and F.shape == (4, 6)
    for backend, call in calls.items():
        back = np.stack([call("contact_inverse_dynamics", *x) for x in zip(q, qd, qdd, F)])
        np.testing.assert_allclose(back, tau, rtol=1e-10, atol=1e-10, err_msg=backend)
    # the batch call equals the single calls
    batch = np_module["contact_inverse_dynamics"](q, qd, qdd, F)
    np.testing.assert_allclose(batch, tau, rtol=1e-10, atol=1e-10)


def _cone_reference(F, normals, mus):
    cone, pyramid = [], []
    for k, (n, mu) in enumerate(zip(normals, mus)):
        f = F[3 * k:3 * k + 3]
        fn = f @ n
        cone.append(mu * fn - np.linalg.norm(f - fn * n))
        axis = np.eye(3)[np.argmin(np.abs(n))]
        t1 = axis - (axis @ n) * n
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(n, t1)
        a = mu / np.sqrt(2)
        pyramid += [a * fn - f @ t1, a * fn + f @ t1, a * fn - f @ t2, a * fn + f @ t2]
    return np.array(cone), np.array(pyramid)


def test_friction_margins_in_every_backend(arm):
    model, calls, modules = arm
    normals = [np.array([-1.0, 0, 0]), np.array([0, 1.0, 0])]
    cd = ContactDynamics(model, model.contacts)
    assert tuple(modules["numpy"]["PYRAMID_ROWS"])[:2] == (
        f"{model.contacts[0].name}.-t1", f"{model.contacts[0].name}.+t1")
    rng = np.random.default_rng(11)
    forces = rng.uniform(-3, 3, (5, 6))
    cone, pyramid = zip(*(_cone_reference(F, normals, (0.5, 0.8)) for F in forces))
    for backend, call in calls.items():
        for F, c, p in zip(forces, cone, pyramid):
            np.testing.assert_allclose(call("friction_cone_margin", F), c, rtol=1e-12,
                                       atol=1e-12, err_msg=backend)
            np.testing.assert_allclose(call("friction_pyramid_margins", F), p, rtol=1e-12,
                                       atol=1e-12, err_msg=backend)
    # the exact margin is eomgen.numeric.contacts' numeric cone check
    for F, c in zip(forces, cone):
        np.testing.assert_allclose([m for _, m in cd.friction_cone(F)], c, rtol=1e-12)
    # batch shapes, and the sign at the cone's edge: f_t = μ f_n (1 ± 1e-6)
    np_module = modules["numpy"]
    assert np_module["friction_cone_margin"](forces).shape == (5, 2)
    assert np_module["friction_pyramid_margins"](forces).shape == (5, 8)
    inside = np.array([-10.0, 5 * (1 - 1e-6), 0, 0, 10.0, 8 * (1 - 1e-6)])
    outside = np.array([-10.0, 5 * (1 + 1e-6), 0, 0, 10.0, 8 * (1 + 1e-6)])
    assert (np_module["friction_cone_margin"](inside) > 0).all()
    assert (np_module["friction_cone_margin"](outside) < 0).all()
    # inside the pyramid implies inside the cone
    many = rng.uniform(-3, 3, (200, 6)) + np.array([-4, 0, 0, 0, 4, 0])
    in_pyramid = (np_module["friction_pyramid_margins"](many).reshape(200, 2, 4) >= 0).all(-1)
    assert in_pyramid.any() and (np_module["friction_cone_margin"](many)[in_pyramid] >= 0).all()


def test_body_jacobian_dot_qd_is_the_time_derivative_of_the_body_twist(arm):
    model, calls, modules = arm
    rng = np.random.default_rng(2)
    q, qd = rng.uniform(-1, 1, (2, 2))
    h = 1e-6
    Jb = modules["numpy"]["frame_body_jacobians"]
    fd = (Jb(q + h * qd) @ qd - Jb(q - h * qd) @ qd) / (2 * h)
    for backend, call in calls.items():
        np.testing.assert_allclose(call("frame_body_jacobians_dot_qd", q, qd), fd, atol=1e-8,
                                   err_msg=backend)


def test_wrong_force_length_is_a_one_line_error(arm):
    model, calls, modules = arm
    for backend in sorted(set(BACKENDS) - {"casadi"}):  # CasADi checks its input sizes itself
        with pytest.raises(ValueError, match=r"F_c must have shape \(6,\)"):
            modules[backend]["friction_cone_margin"](np.zeros(2))


def test_cone_outputs_need_mu_and_contacts():
    robot = eomgen.load(eomgen.example_path("planar_2link"))
    with pytest.raises(GenerationError, match="has no friction coefficient"):
        eomgen.derive(apply_scene(robot, load_scene("w.yaml", text=(
            "version: 1\ncontacts:\n  - {frame: tip}\n"))).model, outputs=("cone_c",))
    with pytest.raises(GenerationError, match="need contacts"):
        eomgen.derive(robot, outputs=("tau_c",))


def test_cli_generates_the_contact_inverse_dynamics(tmp_path):
    scene = tmp_path / "wall.yaml"
    scene.write_text(SCENE)
    out = tmp_path / "out"
    run = run_in_process("generate", "--scene", scene, "--no-cache", "--outputs",
                         "contact_inverse_dynamics,friction_cone_margin", "--backend", "numpy",
                         "-o", out, "--quiet")
    assert run.returncode == 0, run.stderr
    text = next(out.glob("*.py")).read_text()
    assert "def contact_inverse_dynamics(q, qd, qdd, F_c" in text
    assert "F_c : array, shape (6,) or (N, 6)" in text
    bad = tmp_path / "bad.yaml"
    bad.write_text("version: 1\nrobot: planar_2link\ncontacts:\n  - {frame: tip}\n")
    run = run_in_process("generate", "--no-cache", "--scene", bad, "--outputs",
                         "friction_cone_margin", "-o", tmp_path / "none", "--quiet")
    assert run.returncode == 2 and not (tmp_path / "none").exists()
    assert len(run.stderr.strip().splitlines()) == 1 and "friction coefficient" in run.stderr
