"""The rule for numbers read from files (eomgen.model.numbers): finite and of magnitude at most
1e12, in every format (URDF, MJCF through MuJoCo's compiler, eomgen YAML, DH tables) and in
scenes; a number that breaks it is an InvalidNumberError naming the file, the element and the
attribute, and ``eomgen generate`` exits 2 with that one line and writes nothing. Numbers that
do not enter the equations of motion (URDF joint limits, MJCF joint ranges) may mean "no
limit" (inf, 1e16) and are read."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import eomgen
from eomgen.errors import ForbiddenXMLError, InvalidNumberError, SceneError
from eomgen.model import MAX_MAGNITUDE
from eomgen.parsers.urdf import joint_limits
from support import ERROR, run_cli, write
from support.extras import need

# -- descriptions, each with one slot for the number under test ---------------------------------

URDF = """<robot name="r">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.1 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="{ixy}" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="{lower}" upper="{upper}" effort="10" velocity="{velocity}"/>
  </joint>
</robot>
"""
URDF_OK = dict(ixy="0", lower="-1", upper="1", velocity="2")

YAML = """name: r
parameters: {{l: {{value: {length}}}}}
links:
  - {{name: base}}
  - {{name: arm, mass: {mass}, com: [l/2, 0, 0], inertia: {{ixx: 0.01, iyy: 0.01, izz: 0.01}}}}
joints:
  - {{name: j1, type: revolute, parent: base, child: arm, axis: [0, 0, 1]}}
"""
YAML_OK = dict(length="0.5", mass="2")

DH = """name: r
convention: standard
dh:
  - {{name: j1, type: revolute, a: {a}, alpha: 0, d: 0, theta: 0,
     mass: 1, com: [0, 0, 0], inertia: {{ixx: 0.1, iyy: 0.1, izz: 0.1}}}}
"""

MJCF = """<mujoco model="m">
  <option gravity="{gravity}"/>
  <worldbody>
    <body name="upper" pos="{pos}">
      <joint name="hip" axis="0 1 0" range="{range}" armature="{armature}" damping="0.1"
             stiffness="1" springref="{springref}"/>
      <geom name="thigh" type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04" mass="{mass}"/>
      <body name="lower" pos="0 0 -0.4">
        <joint name="knee" axis="0 1 0"/>
        <geom type="sphere" size="0.05" mass="1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
MJCF_OK = dict(gravity="0 0 -9.81", pos="0 0 1", range="-1 1", armature="0.01", springref="0",
               mass="2")

SCENE_ROBOT = "planar_2link"


def urdf(tmp_path, **values) -> Path:
    return write(tmp_path / "robot.urdf", URDF.format(**{**URDF_OK, **values}))


def mjcf(tmp_path, **values) -> Path:
    return write(tmp_path / "robot.xml", MJCF.format(**{**MJCF_OK, **values}))


def refused(path, element: str, problem: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the MJCF spring is warned about
        with pytest.raises(InvalidNumberError) as caught:
            eomgen.load(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: {element}: "), message
    assert problem in message and "\n" not in message
    return message


# -- every format -------------------------------------------------------------------------------

@pytest.mark.parametrize("text, problem", [("inf", "is not a finite"),
                                           ("-3e13", "is out of range"),
                                           ("1e300", "is out of range")])
def test_urdf_inertia(tmp_path, text, problem):
    refused(urdf(tmp_path, ixy=text), "link 'arm' <inertial><inertia>", f"ixy '{text}' {problem}")


@pytest.mark.parametrize("mass, problem", [(".nan", "not a finite"), ("2.0e+13", "out of range"),
                                           ("10**13", "out of range")])
def test_yaml_link_mass(tmp_path, mass, problem):
    refused(write(tmp_path / "r.yaml", YAML.format(**{**YAML_OK, "mass": mass})),
            "links[1] 'arm' mass", problem)


def test_yaml_expression_at_the_parameter_defaults(tmp_path):
    """Each number of ``l/2`` keeps the rule, its value at l = 1e12 does not... and l**2 more
    so: the model's numbers are checked at the parameters' defaults too."""
    text = YAML.format(**{**YAML_OK, "length": "1e12"}).replace("l/2", "l*l")
    refused(write(tmp_path / "r.yaml", text), "link 'arm' inertial",
            "centre of mass entry (at the parameters' default values) 1e+24 is out of range")


@pytest.mark.parametrize("a, problem", [("1.0e+20", "out of range"), (".inf", "not a finite")])
def test_dh_length(tmp_path, a, problem):
    refused(write(tmp_path / "dh.yaml", DH.format(a=a)), "dh[0] 'j1' a", problem)


MJCF_CASES = {
    "body pos 1e300": (dict(pos="0 1e300 1"), "body 'upper'", "pos is out of range"),
    "geom mass 1e300": (dict(mass="1e300"), "body 'upper'", "mass (of its <inertial> or its "
                        "geoms) is out of range"),
    "armature inf": (dict(armature="inf"), "joint 'hip'", "armature is not a finite number"),
    "springref -1e20 degrees": (dict(springref="-1e20"), "joint 'hip'",
                                "springref is out of range (magnitude above 1e+12): MuJoCo "
                                "compiled it to -1.74533e+18"),
    "gravity 1e200": (dict(gravity="0 0 -1e200"), "option", "gravity is out of range"),
}


@pytest.mark.parametrize("case", MJCF_CASES)
def test_mjcf(tmp_path, case):
    need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    values, element, problem = MJCF_CASES[case]
    refused(mjcf(tmp_path, **values), element, problem)


def test_mjcf_equality_inertial_and_damping(tmp_path):
    need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    coupled = MJCF.format(**MJCF_OK).replace(
        "</mujoco>", '<equality><joint name="tie" joint1="knee" joint2="hip" '
        'polycoef="0 -inf 0 0 0"/></equality></mujoco>')
    refused(write(tmp_path / "coupled.xml", coupled), "equality 'tie' (joint)",
            "polycoef is not a finite number")
    inertial = MJCF.format(**MJCF_OK).replace(
        '<body name="lower" pos="0 0 -0.4">',
        '<body name="lower" pos="0 0 -0.4"><inertial pos="0 inf 0" mass="1" diaginertia="1 1 1"/>')
    refused(write(tmp_path / "inertial.xml", inertial), "body 'lower'",
            "centre of mass (of its <inertial> or its geoms) is not a finite number")
    damped = MJCF.format(**MJCF_OK).replace('damping="0.1"', 'damping="5e12"')
    refused(write(tmp_path / "damped.xml", damped), "joint 'hip'", "damping is out of range")


@pytest.mark.parametrize("entry, element", [
    ("payloads: [{link: link2, mass: 3.0e+14}]", "payloads[0] 'payload0' mass"),
    ("parameters: {m_load: 1.0e+7}\npayloads: [{link: link2, mass: m_load**2}]",
     "payloads[0] 'payload0'"),
    ("gravity: [0, 0, -1.0e+13]", "gravity[2]"),
])
def test_scene(tmp_path, entry, element):
    path = write(tmp_path / "scene.yaml", "version: 1\n" + entry + "\n")
    with pytest.raises(InvalidNumberError) as caught:
        eomgen.apply_scene(eomgen.load(SCENE_ROBOT), eomgen.load_scene(path))
    assert isinstance(caught.value, SceneError)
    assert str(caught.value).startswith(f"{path}: {element}")


# -- the command line ---------------------------------------------------------------------------

@pytest.mark.parametrize("make, element", [
    (lambda tmp: urdf(tmp, ixy="-5e12"), "link 'arm' <inertial><inertia>"),
    (lambda tmp: write(tmp / "r.yaml", YAML.format(**{**YAML_OK, "mass": "5e13"})),
     "links[1] 'arm' mass"),
    (lambda tmp: mjcf(tmp, pos="0 0 1e300"), "body 'upper'"),
])
def test_generate_exits_2_with_one_line_and_writes_nothing(tmp_path, make, element):
    path = make(tmp_path)
    if path.suffix == ".xml":
        need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    out = tmp_path / "out"
    result = run_cli("generate", path, "--backend", "numpy", "-o", out)
    assert result.exit_code == 2
    assert result.stderr.startswith(f"{ERROR}{path}: {element}: ")
    assert len(result.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_generate_with_a_scene_payload_out_of_range(tmp_path):
    scene = write(tmp_path / "scene.yaml", "version: 1\npayloads: [{link: link2, mass: -2e12}]\n")
    out = tmp_path / "out"
    result = run_cli("generate", SCENE_ROBOT, "--scene", scene, "--backend", "numpy", "-o", out)
    assert result.exit_code == 2
    assert result.stderr.strip() == (f"{ERROR}{scene}: payloads[0] 'payload0' mass: '-2e12' is "
                                     "out of range (magnitude above 1e+12)")
    assert not out.exists()


# -- what is still read -------------------------------------------------------------------------

def test_numbers_up_to_the_limit_load(tmp_path):
    assert MAX_MAGNITUDE == 1e12
    model = eomgen.load(urdf(tmp_path, ixy="-1e-300"))
    assert float(model.link_by_name["arm"].inertial.inertia[0][1]) == -1e-300
    model = eomgen.load(write(tmp_path / "r.yaml", YAML.format(length="1e12", mass="1e12")))
    assert float(model.link_by_name["arm"].inertial.mass) == MAX_MAGNITUDE


def test_urdf_limits_meaning_no_limit_are_read(tmp_path):
    """URDF joint limits do not enter the equations of motion: ±1e16 and inf (no limit, as in
    example-robot-data's iris) are read; nan is not a limit."""
    path = urdf(tmp_path, lower="-1e16", upper="inf", velocity="1e300")
    assert eomgen.load(path).joint_names == ("shoulder",)
    limit = joint_limits(path)["shoulder"]
    assert (limit.lower, limit.upper, limit.velocity) == (-1e16, float("inf"), 1e300)
    with pytest.raises(InvalidNumberError, match=r"shoulder' <limit>: upper 'nan' is not a "):
        joint_limits(urdf(tmp_path, upper="nan"))


def test_mjcf_joint_ranges_are_not_held_to_the_rule(tmp_path):
    need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the spring
        model = eomgen.load(mjcf(tmp_path, range="-1e16 1e16"))
    assert model.joint_names == ("hip", "knee")


# -- XML with a DTD -----------------------------------------------------------------------------

def test_mjcf_with_entity_declarations_is_refused_as_such(tmp_path):
    text = ('<?xml version="1.0"?>\n<!DOCTYPE mujoco [\n  <!ENTITY big "1e300">\n]>\n'
            + MJCF.format(**MJCF_OK))
    path = write(tmp_path / "entities.xml", text)
    with pytest.raises(ForbiddenXMLError) as caught:
        eomgen.load(path)
    assert str(caught.value) == (f"{path}: <!DOCTYPE>: XML with a DTD, entity declarations or "
                                 "external references is not read (security)")
