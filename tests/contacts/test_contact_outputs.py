"""Frame kinematics and contacts as generated outputs (issue 16): ``frame_*``,
``contact_jacobian``, ``contact_bias`` and the composed ``constrained_forward_dynamics``.

References: the closed form of the planar 2-link arm's tip (position, Jacobian, J̇ q̇) and its
statics against a wall (docs/contact.md), in every backend; Pinocchio's frame placements,
``getFrameJacobian`` (LOCAL_WORLD_ALIGNED, LOCAL), classical frame accelerations and
``constraintDynamics`` (CONTACT_3D) on the floating solo12 with its four feet held, through
eomgen.numeric.floating_base's map to Pinocchio's free flyer; finite differences of the generated positions;
eomgen.numeric.contacts' numeric KKT (Newton–Euler M and h).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import eomgen
from eomgen.codegen import loadable_backends
from support import ROOT, erd_robots_dir, floating_states, run_in_process
from support.reference import pinocchio_contacts
from eomgen.numeric import floating_base
from eomgen.codegen.functions import select_functions
from eomgen.codegen.generate import render_files
from eomgen.numeric.contacts import ContactDynamics
from eomgen.errors import SceneError
from eomgen.outputs import CONSTRAINED_FORWARD, OUTPUTS
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from eomgen.symbolic.frames import output_frames
from support.extras import need

WALL = ROOT / "examples/contacts/planar_2link_wall.yaml"
STANDING = ROOT / "examples/contacts/solo12_standing.yaml"
FRAME_FUNCTIONS = ["frame_positions", "frame_rotations", "frame_jacobians",
                   "frame_body_jacobians", "frame_jacobians_dot_qd"]


def relative(a, b) -> float:
    return float(np.abs(np.asarray(a) - b).max() / np.abs(b).max())


def _write(files, tmp_path):
    """Write the generated files once (rewriting a loaded shared library would crash)."""
    for f in files:
        path = tmp_path / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")


def _load(files, tmp_path, backend, stem):
    """The generated module of ``backend`` (files written by :func:`_write`) as a dict, loaded
    by the backend's registered ``load``."""
    return dict(loadable_backends()[backend].load(tmp_path, stem).namespace)


def _call(module, backend, function, *args):
    if backend == "casadi":
        names = OUTPUTS[function].inputs
        out = module[function].call(dict(zip(names, args)))
        got = np.array(out[OUTPUTS[function].symbol], dtype=float)
        return got.ravel() if OUTPUTS[function].is_vector else got
    return np.asarray(module[function](*args), dtype=float)


# --- the planar arm on a wall: closed form, every backend -------------------------------------

@pytest.mark.slow
def test_planar_wall_outputs_in_every_backend(tmp_path):
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    wall = apply_scene(arm, load_scene(WALL)).model
    assert [c.frame for c in wall.contacts] == ["tip"] and output_frames(wall) == ("tip",)
    functions = select_functions(FRAME_FUNCTIONS + ["constrained_forward_dynamics"])
    have = list(loadable_backends())  # every code backend the registry can load here
    files = render_files(wall, have, functions=functions)
    _write(files, tmp_path)
    values = {s.name: v for s, v in wall.parameter_values.items()}
    l1, l2 = values["l1"], values["l2"]
    q1, q2, w1, w2 = 0.4, 0.9, 0.7, -1.3
    q, qd = np.array([q1, q2]), np.array([w1, w2])
    s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
    p = np.array([l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0])
    Jlin = np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12], [0, 0]])
    J = np.vstack([Jlin, [[0, 0], [0, 0], [1, 1]]])  # [linear; angular]
    w = w1 + w2
    acc = np.array([-l1 * c1 * w1**2 - l2 * c12 * w**2, -l1 * s1 * w1**2 - l2 * s12 * w**2, 0])
    R = np.array([[c12, -s12, 0], [s12, c12, 0], [0, 0, 1]])
    expected = {
        "frame_positions": (p[None, :], (q,)),
        "frame_rotations": (R, (q,)),
        "frame_jacobians": (J, (q,)),
        "frame_body_jacobians": (np.vstack([R.T @ Jlin, J[3:]]), (q,)),
        "frame_jacobians_dot_qd": (np.r_[acc, 0, 0, 0], (q, qd)),
        "contact_jacobian": (Jlin, (q,)),
        "contact_bias": (acc, (q, qd)),
    }
    loaded = {backend: _load(files, tmp_path, backend, "planar_2link") for backend in have}
    for backend, module in loaded.items():
        assert tuple(module["FRAME_NAMES"]) == ("tip",), backend
        assert tuple(module["CONTACT_ROWS"]) == ("tip.f_x", "tip.f_y", "tip.f_z"), backend
        for function, (value, args) in expected.items():
            got = _call(module, backend, function, *args)
            np.testing.assert_allclose(got, value, rtol=1e-12, atol=1e-12,
                                       err_msg=f"{backend} {function}")
        # every code backend composes it (CONSTRAINED_FORWARD.backends is None)
        assert CONSTRAINED_FORWARD.function in module, backend
        if backend not in ("casadi",):
            assert CONSTRAINED_FORWARD.function in module["__all__"], backend
    # statics on the wall (docs/contact.md): τ = g(q) + f (−l1 s1 − l2 s12, −l2 s12) holds the
    # arm still with the wall's force (−f, 0, 0); the z row is zero (planar), so the damped
    # variant is needed
    m1, m2, lc1, lc2, g0 = (values[k] for k in ("m1", "m2", "lc1", "lc2", "g"))
    f = 3.0
    tau = np.array([(m1 * lc1 + m2 * l1) * g0 * c1 + m2 * lc2 * g0 * c12,
                    m2 * lc2 * g0 * c12]) + f * np.array([-l1 * s1 - l2 * s12, -l2 * s12])
    zero = np.zeros(2)
    numpy_module, casadi_module = loaded["numpy"], loaded["casadi"]
    with pytest.raises(np.linalg.LinAlgError, match="dependent rows"):
        numpy_module["constrained_forward_dynamics"](q, zero, tau)
    qdd, F = numpy_module["constrained_forward_dynamics"](q, zero, tau, damping=1e-12)
    assert np.abs(qdd).max() < 1e-9 and np.allclose(F, [-f, 0, 0], atol=1e-8)
    out = casadi_module["constrained_forward_dynamics"].call(
        {"q": q, "qd": zero, "tau": tau, "damping": 1e-12})
    assert np.abs(np.array(out["qdd"])).max() < 1e-9
    assert np.allclose(np.array(out["F_c"]).ravel(), [-f, 0, 0], atol=1e-8)
    # moving, against the numeric KKT (damped alike)
    cd = ContactDynamics(wall, wall.contacts)
    tau = np.array([1.0, -2.0])
    qdd_ref, F_ref = cd.constrained_forward_dynamics(q, qd, tau, damping=1e-9)
    qdd, F = numpy_module["constrained_forward_dynamics"](q, qd, tau, damping=1e-9)
    assert relative(qdd, qdd_ref) < 1e-10 and relative(F, F_ref) < 1e-10
    out = casadi_module["constrained_forward_dynamics"](
        q, qd, tau, *casadi_module["PARAMETERS"].values(), 1e-9)  # positional: PARAMETERS order
    assert relative(np.array(out[0]).ravel(), qdd_ref) < 1e-10
    assert relative(np.array(out[1]).ravel(), F_ref) < 1e-10
    for backend in sorted(set(loaded) - {"numpy", "casadi"}):  # the others, called alike
        args = (q, qd, tau)
        qdd, F = loaded[backend]["constrained_forward_dynamics"](*args, damping=1e-9)
        assert relative(np.asarray(qdd, dtype=float), qdd_ref) < 1e-10, backend
        assert relative(np.asarray(F, dtype=float), F_ref) < 1e-10, backend


# --- solo12 with a floating base and four feet held (Pinocchio) -------------------------------

@pytest.fixture(scope="module")
def solo(tmp_path_factory):
    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    import warnings

    path = erd_robots_dir() / "solo_description/robots/solo12.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = apply_scene(eomgen.load(path), dataclasses.replace(
            load_scene(STANDING), floating_base="euler")).model  # the Euler chart's map
    functions = select_functions(FRAME_FUNCTIONS + ["constrained_forward_dynamics"])
    files = render_files(model, ["numpy", "casadi"], functions=functions)
    tmp = tmp_path_factory.mktemp("solo")
    _write(files, tmp)
    return (path, model, _load(files, tmp, "numpy", model.name),
            _load(files, tmp, "casadi", model.name))


def _states(count, seed):
    return floating_states(18, count, seed, accelerations=True)


@pytest.mark.slow
def test_solo_frames_match_pinocchio_and_finite_differences(solo):
    pin = need("pinocchio", reason="Pinocchio is the reference")
    path, model, np_module, ca_module = solo
    feet = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
    assert tuple(np_module["FRAME_NAMES"]) == feet  # the contact frames, by the rule
    ref = floating_base.PinocchioFreeFlyer(path, model.joint_names)
    pm, pd, idx = ref.model, ref.data, ref.idx
    for q, qd, _ in _states(2, 5):
        q_pin, v = ref.state(q, qd)
        T = floating_base.velocity_map(q)  # Pinocchio's v = T q̇ (base twist from Euler rates)
        pin.forwardKinematics(pm, pd, q_pin, v, floating_base.velocity_map_dot_qd(q, qd)[idx])
        pin.updateFramePlacements(pm, pd)
        pin.computeJointJacobians(pm, pd, q_pin)
        got = {f: np_module[f](q, qd) if f == "frame_jacobians_dot_qd" else np_module[f](q)
               for f in FRAME_FUNCTIONS}
        J_ca = np.array(ca_module["frame_jacobians"](q), dtype=float)
        np.testing.assert_allclose(J_ca, got["frame_jacobians"], rtol=0, atol=1e-13)
        for k, name in enumerate(feet):
            fid = pm.getFrameId(name)
            assert np.allclose(got["frame_positions"][k], pd.oMf[fid].translation, atol=1e-14)
            assert np.allclose(got["frame_rotations"][3 * k:3 * k + 3], pd.oMf[fid].rotation,
                               atol=1e-14)
            for frame, key in ((pin.LOCAL_WORLD_ALIGNED, "frame_jacobians"),
                               (pin.LOCAL, "frame_body_jacobians")):
                J = np.empty((6, 18))
                J[:, idx] = pin.getFrameJacobian(pm, pd, fid, frame)
                assert np.allclose(J @ T, got[key][6 * k:6 * k + 6], atol=1e-13)
            acc = pin.getFrameClassicalAcceleration(pm, pd, fid, pin.LOCAL_WORLD_ALIGNED)
            assert np.allclose(np.r_[acc.linear, acc.angular],
                               got["frame_jacobians_dot_qd"][6 * k:6 * k + 6], atol=1e-12)
        # the linear rows are the derivative of the positions (central differences)
        h = 1e-6
        fd = np.stack([(np_module["frame_positions"](q + h * e) - np_module["frame_positions"](
            q - h * e)) / (2 * h) for e in np.eye(18)], axis=-1)  # (nf, 3, n)
        lin = got["frame_jacobians"].reshape(4, 6, 18)[:, :3]
        assert np.abs(fd - lin).max() < 1e-8
        # and J̇ q̇ is the derivative of J q̇ along q̇
        Jqd = lambda x: np_module["frame_jacobians"](x) @ qd  # noqa: E731
        assert np.abs((Jqd(q + h * qd) - Jqd(q - h * qd)) / (2 * h)
                      - got["frame_jacobians_dot_qd"]).max() < 1e-7


@pytest.mark.slow
def test_solo_constrained_dynamics_matches_pinocchio_and_the_numeric_kkt(solo):
    pin = need("pinocchio", reason="Pinocchio is the reference")
    path, model, np_module, ca_module = solo
    assert len(np_module["CONTACT_ROWS"]) == 12 and np_module["CONTACT_ROWS"][0] == "FL_FOOT.f_x"
    cd = ContactDynamics(model, model.contacts)
    ref = floating_base.PinocchioFreeFlyer(path, model.joint_names)
    pm, pd, idx = ref.model, ref.data, ref.idx
    models, datas = pinocchio_contacts(pm, pd, [c.frame for c in model.contacts])
    for q, qd, tau in _states(3, 8):
        q_pin, v = ref.state(q, qd)
        T = floating_base.velocity_map(q)
        a = pin.constraintDynamics(pm, pd, q_pin, v, np.linalg.solve(T.T, tau)[idx], models,
                                   datas, pin.ProximalSettings(1e-14, 1e-12, 1))
        a_ours = np.empty(18)
        a_ours[idx] = a
        qdd_pin = np.linalg.solve(T, a_ours - floating_base.velocity_map_dot_qd(q, qd))
        qdd_kkt, F_kkt = cd.constrained_forward_dynamics(q, qd, tau)
        np.testing.assert_allclose(np_module["contact_jacobian"](q), cd.contact_jacobian(q),
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(np_module["contact_bias"](q, qd), cd.contact_bias(q, qd),
                                   rtol=0, atol=1e-11)
        qdd, F = np_module["constrained_forward_dynamics"](q, qd, tau)
        out = ca_module["constrained_forward_dynamics"].call({"q": q, "qd": qd, "tau": tau})
        qdd_ca, F_ca = (np.array(out[k], dtype=float).ravel() for k in ("qdd", "F_c"))
        for name, (x, f) in {"numpy": (qdd, F), "casadi": (qdd_ca, F_ca),
                             "numeric KKT": (qdd_kkt, F_kkt)}.items():
            assert relative(x, qdd_pin) <= 1e-8, name
            assert relative(f, pd.lambda_c) <= 1e-8, name
    # a batch of states gives the batch of results
    states = list(_states(2, 9))
    qdd_b, F_b = np_module["constrained_forward_dynamics"](*(np.array(x) for x in zip(*states)))
    for k, (q, qd, tau) in enumerate(states):
        qdd, F = np_module["constrained_forward_dynamics"](q, qd, tau)
        assert np.allclose(qdd_b[k], qdd, rtol=1e-12) and np.allclose(F_b[k], F, rtol=1e-12)


# --- the frame rule, the CLI route and bad requests ---------------------------------------------

def test_frame_rule_leaf_links_then_contacts_then_scene_frames():
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    assert output_frames(arm) == ("tip",)  # no scene: the leaf links
    scene = load_scene("s.yaml", text="version: 1\nframes: [link1, tip]\n"
                       "contacts: [{frame: tip}]\n")
    assert output_frames(apply_scene(arm, scene).model) == ("link1", "tip")


@pytest.mark.parametrize("text, message", [
    ("frames: [tip, hand]", "s.yaml: frames[1]: no link 'hand' in robot 'planar_2link'"),
    ("frames: [tip, tip]", "s.yaml: frames[1]: frame 'tip' is listed twice"),
    ("frames: [3]", "s.yaml: frames[0]: expected a link name"),
])
def test_bad_scene_frames_are_one_line_errors(text, message):
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    with pytest.raises(SceneError) as info:
        apply_scene(arm, load_scene("s.yaml", text="version: 1\n" + text + "\n"))
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def _cli(*args):
    return run_in_process("generate", *args, "--no-cache", "--quiet")


def test_cli_generates_contact_outputs_and_refuses_them_without_contacts(tmp_path):
    out = tmp_path / "wall"
    result = _cli("--backend", "numpy", "--scene", str(WALL), "--outputs",
                  "J_c,contact_bias,frame_positions", "-o", str(out))
    assert result.returncode == 0, result.stderr
    text = (out / "planar_2link_numpy.py").read_text()
    assert "def contact_jacobian(q" in text and "CONTACT_ROWS = (" in text
    assert "FRAME_NAMES = (" in text and "def mass_matrix(" not in text
    bare = tmp_path / "bare"
    result = _cli("--backend", "numpy", "--outputs", "contact_jacobian", "-o", str(bare))
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "planar_2link.yaml" in lines[0] and "has none" in lines[0]
    assert not bare.exists()


def test_documented_frame_errors_are_what_eomgen_prints():
    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = eomgen.load(erd_robots_dir() / "solo_description/robots/solo12.urdf")
    text = (ROOT / "docs/scenes.md").read_text(encoding="utf-8")
    documented = [line[len("eomgen: error: "):] for line in text.splitlines()
                  if line.startswith("eomgen: error: solo_frames.yaml")]
    printed = []
    for body in ("frames: [FL_FOOT, FL_FOT]", "frames: [FL_FOOT, FL_FOOT]"):
        with pytest.raises(SceneError) as caught:
            apply_scene(robot, load_scene("solo_frames.yaml", text="version: 1\n" + body))
        printed.append(str(caught.value))
    assert printed == documented and len(printed) == 2


def test_fixed_base_frames_are_pinocchios_local_world_aligned_jacobians(tmp_path):
    """On a fixed-base arm (UR5) block k of frame_jacobians is Pinocchio's
    getFrameJacobian(LOCAL_WORLD_ALIGNED) as it stands ([v; ω], linear rows first). The
    tolerance is that of the two readers' rotations of the URDF's rounded rpy values
    (differences of 5e-12 observed)."""
    pin = need("pinocchio", reason="Pinocchio is the reference")
    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    import warnings

    path = erd_robots_dir() / "ur_description/urdf/ur5_robot.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        arm = apply_scene(eomgen.load(path), load_scene(
            "f.yaml", text="version: 1\nframes: [tool0, forearm_link]\n")).model
    files = render_files(arm, ["numpy"], functions=select_functions(
        FRAME_FUNCTIONS + ["frame_body_jacobians_dot_qd"]))
    _write(files, tmp_path)
    module = _load(files, tmp_path, "numpy", arm.name)
    assert tuple(module["FRAME_NAMES"]) == ("tool0", "forearm_link")
    pm = pin.buildModelFromUrdf(str(path))
    pd = pm.createData()
    assert tuple(pm.names)[1:] == arm.joint_names
    rng = np.random.default_rng(4)
    q, qd = rng.uniform(-2, 2, 6), rng.uniform(-1, 1, 6)
    pin.forwardKinematics(pm, pd, q, qd, np.zeros(6))
    pin.updateFramePlacements(pm, pd)
    pin.computeJointJacobians(pm, pd, q)
    J, Jb, dJqd = (module["frame_jacobians"](q), module["frame_body_jacobians"](q),
                   module["frame_jacobians_dot_qd"](q, qd))
    for k, name in enumerate(module["FRAME_NAMES"]):
        fid = pm.getFrameId(name)
        rows = slice(6 * k, 6 * k + 6)
        np.testing.assert_allclose(
            J[rows], pin.getFrameJacobian(pm, pd, fid, pin.LOCAL_WORLD_ALIGNED), atol=1e-10)
        np.testing.assert_allclose(Jb[rows], pin.getFrameJacobian(pm, pd, fid, pin.LOCAL),
                                   atol=1e-10)
        acc = pin.getFrameClassicalAcceleration(pm, pd, fid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(dJqd[rows], np.r_[acc.linear, acc.angular], atol=1e-10)
        # the body J̇ q̇: Pinocchio's spatial frame acceleration in LOCAL at q̈ = 0
        acc = pin.getFrameAcceleration(pm, pd, fid, pin.LOCAL)
        np.testing.assert_allclose(module["frame_body_jacobians_dot_qd"](q, qd)[rows],
                                   np.r_[acc.linear, acc.angular], atol=1e-10)
        np.testing.assert_allclose(module["frame_positions"](q)[k], pd.oMf[fid].translation,
                                   atol=1e-12)


def test_contact_inverse_dynamics_and_the_cone_are_generated_not_listed_as_not_done(tmp_path):
    """Issue 29: docs/contact.md listed contact inverse dynamics and the friction cone under
    "Not done yet" beside its own table saying every backend generates them; the command
    generates both, and the list no longer names them."""
    scene = tmp_path / "wall.yaml"
    scene.write_text(WALL.read_text(encoding="utf-8").replace(
        "normal: [-1, 0, 0]}", "normal: [-1, 0, 0], mu: 0.5}"), encoding="utf-8")
    out = tmp_path / "out"
    result = run_in_process("generate", "--scene", scene, "--backend", "numpy", "--outputs",
                            "contact_inverse_dynamics,friction_cone_margin", "-o", out,
                            "--no-cache", "--quiet")
    assert result.returncode == 0, result.stderr
    text = (out / "planar_2link_numpy.py").read_text(encoding="utf-8")
    for function in ("contact_inverse_dynamics", "friction_cone_margin"):
        assert f"def {function}(" in text and OUTPUTS[function].backends is None
    docs = (ROOT / "docs/contact.md").read_text(encoding="utf-8")
    not_done = docs.split("## Not done yet", 1)[1].split("\n## ", 1)[0].lower()
    assert "inverse dynamics" not in not_done and "friction cone" not in not_done
