"""Robots and descriptions that tests in several feature folders use.

* hand-written URDF text: :func:`robot`, :func:`link`, :func:`joint` and a legged trunk
  (:func:`legged`), whose root looks like a floating base;
* example-robot-data robots: the Panda with its fingers locked (:func:`panda`), the UR5, the
  solo12 path (:data:`SOLO`) and Pinocchio's free flyer as its reference;
* the hostile-names robot (:func:`hostile_star`): names that try to break out of the string
  literals, docstrings and comments they end up in;
* the flexible 2-link arm with drives (:func:`drive_arm`);
* the planar two-link arm whose second joint is turned about z (:func:`turned_arm_yaml`,
  :func:`turned_arm_urdf`): exact and float rotation angles;
* the MJCF bodies of the actuator tests (:data:`MJCF_ARM_WITH_TENDON`): two hinges and a
  slide joint with a fixed tendon across the last two, contacts off, an ``<actuator>`` to
  follow.

Each function builds a fresh model (models are frozen data, but tests that cache a derivation
do so in their own module).
"""

from __future__ import annotations

import math
from dataclasses import replace
from xml.sax.saxutils import quoteattr


import eomgen
from eomgen.numeric.floating_base import PinocchioFreeFlyer as FreeFlyerReference  # noqa: F401  (re-export)
from eomgen.model import Actuator, Inertial, Joint, JointType, Link, RobotModel, Transform
from eomgen.model import build_model, vec3

from . import ROOT, erd_robots_or_skip, load_quietly

# ----------------------------------------------------------------------------------------------
# Hand-written URDFs
# ----------------------------------------------------------------------------------------------


#: Two hinges and a slide joint in a chain with a fixed tendon ``t`` across j2 and j3, contacts
#: off: the MJCF body of the DC motor and PID tests, which append their ``<actuator>``.
MJCF_ARM_WITH_TENDON = """<option timestep="0.004"><flag contact="disable"/></option><worldbody>
<body><joint name="j1" axis="0 1 0" damping="0.01"/>
 <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/>
 <body pos=".3 0 0"><joint name="j2" axis="0 1 0"/><geom type="capsule" size=".05"
   fromto="0 0 0 .3 0 0"/>
  <body pos=".3 0 0"><joint name="j3" type="slide" axis="1 0 0"/><geom size=".05"/></body>
 </body></body></worldbody>
<tendon><fixed name="t"><joint joint="j2" coef="0.5"/><joint joint="j3" coef="-1"/></fixed>
</tendon>"""


def robot(*parts: str, name: str = "r") -> str:
    return f"<robot name={quoteattr(name)}>" + "".join(parts) + "</robot>"


INERTIA = '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'


def link(name: str, inertial: str | None = f'<inertial><mass value="1"/>{INERTIA}</inertial>'
         ) -> str:
    return f"<link name={quoteattr(name)}>{inertial or ''}</link>"


def joint(name: str, parent: str, child: str, kind: str = "revolute",
          body: str = '<axis xyz="0 0 1"/>') -> str:
    return (f"<joint name={quoteattr(name)} type={quoteattr(kind)}>"
            f"<parent link={quoteattr(parent)}/><child link={quoteattr(child)}/>{body}</joint>")


def legged(direction=(0, 0, -1), legs: int = 4, length: float = 0.3, hip: float = 0.2,
           world: bool = False, massless_root: bool = False) -> str:
    """A trunk with ``legs`` two-joint branches, each reaching ``length`` along ``direction``
    from a hip ``hip`` metres out of the trunk's centre (at q = 0). ``world``: bolted to a
    ``world`` root link; ``massless_root``: a massless root fixed to the massive trunk, as
    ANYmal and Go1 are written."""
    parts = [link("trunk")]
    if world:
        parts += [link("world", None), joint("bolt", "world", "trunk", "fixed", "")]
    if massless_root:
        parts += [link("base", None), joint("base_to_trunk", "base", "trunk", "fixed", "")]
    half = " ".join(f"{length / 2 * d:g}" for d in direction)
    for k in range(legs):
        angle = 2 * math.pi * k / legs
        at = f"{hip * math.cos(angle):.6g} {hip * math.sin(angle):.6g} 0"
        parts += [link(f"thigh{k}"), link(f"shin{k}"), link(f"foot{k}", None),
                  joint(f"hip{k}", "trunk", f"thigh{k}",
                        body=f'<origin xyz="{at}"/><axis xyz="0 1 0"/>'),
                  joint(f"knee{k}", f"thigh{k}", f"shin{k}",
                        body=f'<origin xyz="{half}"/><axis xyz="0 1 0"/>'),
                  joint(f"sole{k}", f"shin{k}", f"foot{k}", "fixed", f'<origin xyz="{half}"/>')]
    return robot(*parts, name="legged")


# ----------------------------------------------------------------------------------------------
# example-robot-data
# ----------------------------------------------------------------------------------------------

#: The solo12 quadruped, below example-robot-data's ``robots/``.
SOLO = "solo_description/robots/solo12.urdf"


def puma() -> RobotModel:
    """PUMA 560 from its bundled DH table."""
    return eomgen.load(eomgen.example_path("puma560_dh"))


def puma_arm() -> RobotModel:
    """The PUMA 560 with its wrist locked: a 3-joint arm with float parameters."""
    from eomgen.model import lock_joints

    return lock_joints(puma(), {"joint4": 0, "joint5": 0, "joint6": 0})


def panda() -> RobotModel:
    """The Panda with its finger joints locked at 0 (skips without example-robot-data)."""
    robots = erd_robots_or_skip()
    from eomgen.model import lock_joints

    model = eomgen.load(robots / "panda_description" / "urdf" / "panda.urdf")
    locked = lock_joints(model, {n: 0 for n in model.joint_names if "finger" in n})
    assert not locked.couplings  # finger_joint2 <mimic> finger_joint1: locked with its leader
    return locked


def ur5() -> RobotModel:
    """The UR5 (skips without example-robot-data)."""
    return load_quietly(erd_robots_or_skip() / "ur_description" / "urdf" / "ur5_robot.urdf")


# ----------------------------------------------------------------------------------------------
# Hostile names
# ----------------------------------------------------------------------------------------------

#: Names that try to break out of the string literals, docstrings and comments they end up in.
HOSTILE = ('a"); import os #', "\\input{/etc/passwd}", "x\n__import__('os').system('echo pwned')",
           "'''", '"""', "ø∂")
#: A robot name that is valid Python once a docstring quoting it ends early.
DOCSTRING_BREAKER = '"""+__import__("os").system("echo pwned")+"""'


def hostile_star(robot_name: str) -> RobotModel:
    """One body per hostile name, each on its own joint (same name) from the base."""
    links = [Link("base")]
    joints = []
    for k, name in enumerate(HOSTILE):
        m = 1.0 + k
        links.append(Link(name, Inertial(m, [0.1 * k, 0.05, -0.1],
                                         [[0.02, 0, 0], [0, 0.03, 0], [0, 0, 0.04]])))
        kind = JointType.PRISMATIC if k % 3 == 1 else JointType.REVOLUTE
        axis = vec3([(0, 0, 1), (0, 1, 0), (1, 0, 0)][k % 3])
        joints.append(Joint(name, kind, "base", name, Transform.from_xyz_rpy([0.1, 0.2 * k, 0]),
                            axis))
    links.append(Link("tool ⟨\"'⟩"))
    joints.append(Joint("fixed */ /*", JointType.FIXED, HOSTILE[0], "tool ⟨\"'⟩",
                        Transform.from_xyz_rpy([0, 0, 0.2])))
    return build_model("hostile \"\"\" source */", robot_name, links, joints,
                       gravity=(0.3, -0.2, -9.81))


# ----------------------------------------------------------------------------------------------
# Drives
# ----------------------------------------------------------------------------------------------

#: The flexible-joint 2-link arm of the examples.
FLEXIBLE_2LINK = ROOT / "examples/robots/flexible_2link.yaml"


def drive_arm() -> RobotModel:
    """The flexible 2-link arm with joint 1 made rigid and given armature and friction; joint 2
    flexible (K2, B2 from the description) with motor friction."""
    model = eomgen.load(FLEXIBLE_2LINK)
    drives = {"joint1": Actuator(armature=0.3, damping=0.4, friction=0.2, friction_width=0.5)}
    joints = tuple(replace(j, actuator=drives.get(j.name, replace(
        j.actuator, damping=0.05, friction=0.1, friction_width=0.5)) if j.actuator else j.actuator)
        for j in model.joints)
    return replace(model, joints=joints)


# ----------------------------------------------------------------------------------------------
# A joint with a turned origin
# ----------------------------------------------------------------------------------------------


def turned_arm_yaml(angle: str = "pi/6") -> str:
    """The planar two-link arm (joints about z) in eomgen's YAML, its second joint's origin
    turned by ``angle`` (text, e.g. ``pi/6``) about z; parameters with integer values, so that
    :func:`turned_arm_urdf` is the same model at those values. M₁₁ = m₁ l_c1² + m₂ (l₁² +
    l_c2² + 2 l₁ l_c2 cos(q₂ + angle)) + I₁ + I₂."""
    return f"""name: turned_2r
gravity: [0, -g, 0]
parameters:
  m1: 1
  m2: 2
  l1: 2
  lc1: 1
  lc2: 1
  I1: 1
  I2: 1
  g: 9.81
links:
  - name: base
  - {{name: link1, mass: m1, com: [lc1, 0, 0], inertia: {{ixx: I1, iyy: I1, izz: I1}}}}
  - {{name: link2, mass: m2, com: [lc2, 0, 0], inertia: {{ixx: I2, iyy: I2, izz: I2}}}}
joints:
  - {{name: joint1, type: revolute, parent: base, child: link1}}
  - name: joint2
    type: revolute
    parent: link1
    child: link2
    origin: {{xyz: [l1, 0, 0], rpy: [0, 0, {angle}]}}
"""


def turned_arm_urdf(angle: str) -> str:
    """:func:`turned_arm_yaml`'s arm at its parameter values, as a URDF (``angle``: the
    ``rpy`` yaw text, e.g. ``0.5235987755982988``); gravity is URDF's (-z)."""
    return robot(
        '<link name="base"/>',
        f'<link name="link1"><inertial><mass value="1"/><origin xyz="1 0 0"/>{INERTIA}'
        '</inertial></link>',
        f'<link name="link2"><inertial><mass value="2"/><origin xyz="1 0 0"/>{INERTIA}'
        '</inertial></link>',
        '<joint name="joint1" type="revolute"><parent link="base"/><child link="link1"/>'
        '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>',
        '<joint name="joint2" type="revolute"><parent link="link1"/><child link="link2"/>'
        f'<origin xyz="2 0 0" rpy="0 0 {angle}"/><axis xyz="0 0 1"/>'
        '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>',
        name="turned_2r")
