"""YAML ``controls:`` (eomgen.model.Control): read, refused in one line when wrong, and generated
as actuator_forces against the clamps computed here with np.clip (a tendon's length and moment
``gear · c`` too), and forward_dynamics_ctrl against the generated forward_dynamics at those
forces (minus the drive's damping)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import eomgen
from eomgen.errors import DescriptionError
from support.generated import generated

ROBOT = """
name: two
parameters: {kp: 20, kv: 1.5}
links:
  - {name: base}
  - {name: l1, mass: 1.2, com: [0.3, 0, 0], inertia: {izz: 0.02, iyy: 0.03, ixx: 0.01}}
  - {name: l2, mass: 0.7, com: [0.2, 0.01, 0], inertia: {izz: 0.01, iyy: 0.01, ixx: 0.004}}
joints:
  - {name: a, type: revolute, parent: base, child: l1, axis: [0, 1, 0]}
  - {name: b, type: prismatic, parent: l1, child: l2, origin: {xyz: [0.5, 0, 0]},
     axis: [1, 0, 0], actuator: {damping: 0.4}}
controls:
  - {name: servo, joint: a, gear: 2, gain: [kp, 0, 0], bias: [0, -kp, -kv],
     forcerange: [-3, 4]}
  - {name: push, joint: b, gain: 5, ctrlrange: [-1, 0.5]}
  - {name: pull, tendon: {a: 0.5, b: -2}, gear: 1.5, gain: 3, bias: [0.2, -4, -0.5]}
"""


@pytest.fixture(scope="module")
def two(tmp_path_factory):
    folder = tmp_path_factory.mktemp("two")
    (folder / "two.yaml").write_text(ROBOT, encoding="utf-8")
    model = eomgen.load(folder / "two.yaml")
    calls = generated(model, ["actuator_forces", "forward_dynamics_ctrl", "forward_dynamics"],
                      folder, ("numpy",))[0]
    return model, calls["numpy"]


def test_forces_are_the_clamped_affine_laws(two):
    model, call = two
    assert [c.name for c in model.controls] == ["servo", "push", "pull"]
    moment = 1.5 * np.array([0.5, -2])
    rng = np.random.default_rng(2)
    for _ in range(6):
        q, qd, u = rng.uniform(-1, 1, 2), rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 3)
        servo = np.clip(20 * u[0] - 20 * 2 * q[0] - 1.5 * 2 * qd[0], -3, 4)
        push = 5 * np.clip(u[1], -1, 0.5)
        pull = 3 * u[2] + 0.2 - 4 * (moment @ q) - 0.5 * (moment @ qd)
        expected = np.array([2 * servo, push]) + moment * pull
        assert np.allclose(call("actuator_forces", q, qd, u), expected, rtol=1e-14, atol=1e-14)
        tau = expected - np.array([0, 0.4 * qd[1]])
        assert np.allclose(call("forward_dynamics_ctrl", q, qd, u),
                           call("forward_dynamics", q, qd, tau), rtol=1e-12, atol=1e-12)


def test_activation_dynamics_are_mujocos_laws(tmp_path):
    """A filter and an integrator: forward_dynamics_act's act_dot is (clamp(ctrl) − act) / T
    and clamp(ctrl), and its q̈ forward_dynamics at the forces gain · act (+ the servo's
    bias, the prismatic joint's damping)."""
    text = ROBOT[:ROBOT.index("controls:")] + (
        "controls:\n  - {name: lag, joint: a, gain: 4, bias: [0, -2, 0], dynamics: filter, "
        "timeconst: 0.2, ctrlrange: [-1, 1]}\n  - {name: ramp, joint: b, dynamics: integrator}\n")
    (tmp_path / "two.yaml").write_text(text, encoding="utf-8")
    model = eomgen.load(tmp_path / "two.yaml")
    call = generated(model, ["forward_dynamics_act", "forward_dynamics"], tmp_path,
                     ("numpy",))[0]["numpy"]
    q, qd, u, act = np.array([0.3, -0.1]), np.array([0.5, 0.8]), np.array([1.6, -0.4]), \
        np.array([0.7, 0.2])
    tau = np.array([4 * act[0] - 2 * q[0], act[1] - 0.4 * qd[1]])
    expected = np.r_[call("forward_dynamics", q, qd, tau), (1 - act[0]) / 0.2, -0.4]
    assert np.allclose(call("forward_dynamics_act", q, qd, u, act), expected, rtol=1e-12,
                       atol=1e-12)


def test_dc_motors_are_mujocos_laws(tmp_path):
    """A DC motor with a current state (rate-limited, with cogging) on a and one without on b:
    act_dot = clamp(((V − K v)/R − i)/T, ±30), forces K i + A sin(N l + φ) and K/R (V − K v)
    (the prismatic joint's damping besides), q̈ forward_dynamics at those forces."""
    text = ROBOT[:ROBOT.index("controls:")].replace("{kp: 20, kv: 1.5}", "{K: 0.05}") + (
        "controls:\n  - {name: m1, joint: a, gear: 2, dcmotor: {resistance: 2, motorconst: K, "
        "timeconst: 0.01, rate_limit: 30, cogging: [0.02, 4, 0.3]}}\n"
        "  - {name: m2, joint: b, ctrlrange: [-12, 12], dcmotor: {resistance: 1.5, "
        "motorconst: 0.04}}\n")
    (tmp_path / "two.yaml").write_text(text, encoding="utf-8")
    model = eomgen.load(tmp_path / "two.yaml")
    assert [c.dynamics for c in model.controls] == ["dcmotor", None]
    call = generated(model, ["forward_dynamics_act", "forward_dynamics"], tmp_path,
                     ("numpy",))[0]["numpy"]
    q, qd = np.array([0.3, -0.1]), np.array([0.5, 0.8])
    for u, i in ((np.array([6.0, 15.0]), 0.4), (np.array([6.0, -3.0]), 2.9)):
        rate = np.clip(((u[0] - 0.05 * 2 * qd[0]) / 2 - i) / 0.01, -30, 30)
        voltage = np.clip(u[1], -12, 12)
        tau = np.array([2 * (0.05 * i + 0.02 * np.sin(4 * 2 * q[0] + 0.3)),
                        0.04 / 1.5 * (voltage - 0.04 * qd[1]) - 0.4 * qd[1]])
        expected = np.r_[call("forward_dynamics", q, qd, tau), rate]
        assert np.allclose(call("forward_dynamics_act", q, qd, u, [i]), expected, rtol=1e-12,
                           atol=1e-12)
    assert abs(rate) < 30  # the second current is within the rate limit, the first is not


@pytest.mark.parametrize("entry, where", [
    ("{name: c, joint: nowhere}", "controls[0] 'c' joint"),
    ("{name: c, joint: a, ctrlrange: [1, -1]}", "controls[0] 'c' ctrlrange"),
    ("{name: c, joint: a, gain: [1, 2]}", "controls[0] 'c' gain"),
    ("{name: c, joint: a, colour: red}", "controls[0]"),
    ("{name: c}", "controls[0] 'c': expected either 'joint'"),
    ("{name: c, joint: a, tendon: {b: 1}}", "controls[0] 'c': expected either 'joint'"),
    ("{name: c, tendon: [a, b]}", "controls[0] 'c' tendon"),
    ("{name: c, tendon: {a: 1, nowhere: 2}}", "controls[0] 'c' tendon"),
    ("{name: c, joint: a, dynamics: muscle}", "controls[0] 'c' dynamics"),
    ("{name: c, joint: a, timeconst: 0.1}", "controls[0] 'c' timeconst"),
    ("{name: c, joint: a, gain: 2, dcmotor: {resistance: 1, motorconst: 1}}",
     "controls[0] 'c' dcmotor: a DC motor's force is its own: drop gain"),
    ("{name: c, joint: a, dcmotor: {resistance: 1}}", "controls[0] 'c' dcmotor"),
    ("{name: c, joint: a, dcmotor: {resistance: 1, motorconst: 1, rate_limit: 3}}",
     "controls[0] 'c' dcmotor rate_limit"),
])
def test_a_wrong_control_is_refused_in_one_line(tmp_path, entry, where):
    text = ROBOT[:ROBOT.index("controls:")] + f"controls:\n  - {entry}\n"
    (tmp_path / "two.yaml").write_text(text, encoding="utf-8")
    with pytest.raises(DescriptionError, match=re.escape(where)) as caught:
        eomgen.load(tmp_path / "two.yaml")
    assert "\n" not in str(caught.value)


def test_a_model_without_controls_refuses_the_control_outputs():
    with pytest.raises(eomgen.errors.GenerationError, match="need controls"):
        eomgen.derive(eomgen.load(eomgen.example_path("planar_2link")), ["tau_act"])
