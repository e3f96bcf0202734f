"""Acceptance: every number of a description or a scene made hostile, one at a time.

For each format (MJCF, URDF, eomgen YAML, DH, scenes) a small valid file using what eomgen reads
of that format; each number in it is replaced in turn by NaN, ±∞ and ±1e300 (and, where it is
a list, each component on its own). Whatever the file, eomgen must do one of two things:

* refuse it: a :class:`~eomgen.errors.DescriptionError` (or SceneError) whose message is one
  line naming the file; never another exception (a traceback in the CLI);
* or read it, and then the model's numbers are finite: M(q), the bias and g at random states
  of the float Newton–Euler reference (:mod:`eomgen.numeric`) hold no NaN and no ∞. A number
  eomgen does not use may be anything (MuJoCo's ``range`` of an unlimited joint, a colour).

The cases are made here from the files below, hundreds of them; a few go through the CLI
(exit 2, one line, nothing written). The files are small and nothing is derived, so the whole
module runs in seconds.
"""

from __future__ import annotations

import importlib.util
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.errors import EomgenError
from eomgen.model.configuration import integrate, neutral
from eomgen.numeric import M_crba, numeric_model, rnea
from support import run_in_process
from support.extras import need

#: What each number is replaced with.
HOSTILE = ("nan", "-inf", "1e300")

MJCF = """<mujoco model="hostile">
  <option gravity="0 0 -9.81" timestep="0.002"/>
  <worldbody>
    <body name="upper" pos="0 0 1" quat="1 0 0 0">
      <joint name="shoulder" type="hinge" axis="0 1 0" range="-2 2" armature="0.01"
             damping="0.1" ref="0"/>
      <inertial pos="0 0 -0.25" mass="1.5" diaginertia="0.02 0.02 0.003"/>
      <body name="fore" pos="0 0 -0.5" euler="0 0.1 0">
        <joint name="elbow" type="hinge" axis="0 1 0" springref="0.2"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.03" mass="0.8"/>
        <body name="tip" pos="0 0 -0.4">
          <joint name="slide" type="slide" axis="0 0 1" armature="0.02"/>
          <inertial pos="0 0 0" mass="0.3" fullinertia="0.001 0.002 0.003 0 0 0"/>
        </body>
      </body>
    </body>
    <body name="pend" pos="1 0 1">
      <joint name="ball" type="ball" damping="0.05"/>
      <geom type="sphere" pos="0 0 -0.3" size="0.05" mass="0.5"/>
      <body name="pend_arm" pos="0 0 -0.3">
        <joint name="wrist" type="hinge" axis="1 0 0" ref="0.1"/>
        <geom type="box" pos="0 0 -0.1" size="0.02 0.02 0.1" density="500"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint joint1="elbow" joint2="shoulder" polycoef="0.1 0.5 0 0 0"/>
  </equality>
  <actuator>
    <motor joint="shoulder" gear="50"/>
  </actuator>
</mujoco>
"""

URDF = """<robot name="hostile">
  <link name="base"/>
  <link name="upper">
    <inertial><origin xyz="0 0 0.2" rpy="0 0 0"/><mass value="1.5"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.003"/></inertial>
  </link>
  <link name="fore">
    <inertial><origin xyz="0.1 0 0.15" rpy="0.1 0 0"/><mass value="0.8"/>
      <inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.012" iyz="0" izz="0.002"/></inertial>
  </link>
  <link name="tip">
    <inertial><mass value="0.3"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0"
      izz="0.001"/></inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.1" rpy="0 0 0.3"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="10" velocity="3"/>
    <dynamics damping="0.1" friction="0.05"/>
  </joint>
  <joint name="elbow" type="continuous">
    <parent link="upper"/><child link="fore"/><origin xyz="0 0 0.4" rpy="0 0.2 0"/>
    <axis xyz="0 1 0"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="fore"/><child link="tip"/><origin xyz="0.3 0 0"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.2" effort="5" velocity="1"/>
  </joint>
</robot>
"""

YAML = """name: hostile
gravity: [0, 0, -9.81]
links:
  - name: base
  - name: upper
    mass: 1.5
    com: [0, 0, 0.2]
    inertia: {ixx: 0.02, iyy: 0.02, izz: 0.003, ixy: 0.001}
  - name: fore
    mass: 0.8
    com: [0.1, 0, 0.15]
    inertia: {ixx: 0.01, iyy: 0.012, izz: 0.002}
  - name: screw_nut
    mass: 0.2
    com: [0, 0, 0.01]
    inertia: {ixx: 0.0001, iyy: 0.0001, izz: 0.0002}
joints:
  - name: shoulder
    type: revolute
    parent: base
    child: upper
    origin: {xyz: [0, 0, 0.1], rpy: [0, 0, 0.3]}
    axis: [0, 0, 1]
    actuator: {rotor_inertia: 0.0001, gear_ratio: 50, damping: 0.1}
  - name: elbow
    type: revolute
    parent: upper
    child: fore
    origin: {xyz: [0, 0, 0.4], rpy: [0, 0.2, 0]}
    axis: [0, 1, 0]
  - name: screw
    type: helical
    pitch: 0.005
    parent: fore
    child: screw_nut
    origin: {xyz: [0.3, 0, 0]}
    axis: [1, 0, 0]
"""

DH = """name: hostile_dh
convention: standard
gravity: [0, 0, -9.81]
dh:
  - {type: revolute, a: 0.3, alpha: 0.5, d: 0.1, theta: 0.2, mass: 2.0,
     com: [-0.15, 0, 0], inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02}}
  - {type: prismatic, a: 0.0, alpha: 0, d: 0.2, theta: 0.1, mass: 1.0,
     com: [0, 0, -0.1], inertia: {ixx: 0.005, iyy: 0.005, izz: 0.001}}
"""

#: A scene on the bundled elbow_rrr arm: a payload, a lock, gravity.
SCENE = """version: 1
robot: elbow_rrr
gravity: [0, 0, -9.81]
locked: {elbow: 0.4}
payloads:
  - link: link2
    name: tool
    mass: 0.7
    com: [0.05, 0, 0.01]
    inertia: {ixx: 0.001, iyy: 0.002, izz: 0.003}
"""

#: A number in a file: not part of a name (``pend_arm2``), a key or an exponent.
NUMBER = re.compile(r"(?<![\w.\-])-?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")


def _numbers(text: str, skip: tuple[str, ...] = ()) -> list[tuple[int, int, str]]:
    """(start, end, context) of each number of ``text`` that a hostile value replaces; a
    number on a line holding one of ``skip`` (a format's version) is left alone."""
    found = []
    for match in NUMBER.finditer(text):
        line_start = text.rfind("\n", 0, match.start()) + 1
        line_end = text.find("\n", match.end())
        line = text[line_start:line_end if line_end >= 0 else None]
        if any(s in line for s in skip):
            continue
        found.append((match.start(), match.end(), line.strip()))
    return found


FILES = {  # format → (file name, text, lines whose numbers are not the model's)
    "mjcf": ("hostile.xml", MJCF, ()),
    "urdf": ("hostile.urdf", URDF, ()),
    "yaml": ("hostile.yaml", YAML, ()),
    "dh": ("hostile_dh.yaml", DH, ()),
    "scene": ("scene.yaml", SCENE, ("version:",)),
}


def _cases():
    for fmt, (name, text, skip) in FILES.items():
        for k, (start, end, context) in enumerate(_numbers(text, skip)):
            for value in HOSTILE:
                mutated = text[:start] + value + text[end:]
                yield pytest.param(fmt, name, mutated, id=f"{fmt}-{k}-{value}")


CASES = list(_cases())


def test_the_files_are_valid_and_the_cases_many(tmp_path):
    """Each file as written loads (so every refusal below is the hostile number's), and
    there are several hundred cases."""
    for fmt, (name, text, _) in FILES.items():
        if fmt == "mjcf" and importlib.util.find_spec("mujoco") is None:
            continue  # its cases skip, saying why
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        model = _load(fmt, path)
        _check_finite(model)
    assert len(CASES) >= 300, len(CASES)


def _load(fmt: str, path: Path):
    if fmt == "mjcf":
        need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if fmt == "scene":
            from eomgen.reduction import apply_scene, load_for_scene
            from eomgen.scene import load_scene

            scene = load_scene(path)
            return apply_scene(load_for_scene(scene.robot, scene), scene).model
        return eomgen.load(path)


def _check_finite(model) -> None:
    nm = numeric_model(model)
    rng = np.random.default_rng(3)
    for _ in range(2):
        q = integrate(neutral(model), rng.uniform(-1, 1, model.dof), 1.0, model)
        qd = rng.uniform(-1, 1, model.dof)
        M = M_crba(nm, q)
        bias = rnea(nm, q, qd, np.zeros(model.dof))
        g = rnea(nm, q, np.zeros(model.dof), np.zeros(model.dof))
        for name, value in (("M", M), ("bias", bias), ("g", g)):
            assert np.all(np.isfinite(value)), f"{name} is not finite: {value}"


@pytest.mark.parametrize("fmt, name, text", CASES)
def test_a_hostile_number_is_refused_in_one_line_or_harmless(fmt, name, text, tmp_path):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    try:
        model = _load(fmt, path)
    except EomgenError as exc:
        message = str(exc)
        assert "\n" not in message, message
        assert str(path) in message or fmt == "scene", message
        return
    _check_finite(model)


#: A few cases through the command line, one per format.
CLI_CASES = [("mjcf", "mass=\"1.5\"", "mass=\"nan\""), ("urdf", "<mass value=\"0.8\"/>",
             "<mass value=\"inf\"/>"), ("yaml", "pitch: 0.005", "pitch: 1e300"),
             ("dh", "a: 0.3", "a: nan")]


@pytest.mark.parametrize("fmt, old, new", CLI_CASES, ids=[c[0] for c in CLI_CASES])
def test_the_cli_refuses_in_one_line_and_writes_nothing(fmt, old, new, tmp_path):
    name, text, _ = FILES[fmt]
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new), encoding="utf-8")
    out = tmp_path / "out"
    done = run_in_process("generate", path, "-o", out, "--backend", "numpy", "--no-cache")
    assert done.returncode == 2, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith(f"eomgen: error: {path}"), done.stderr
    assert "Traceback" not in done.stderr and not out.exists()
