"""Small models with quaternion joints (a free flyer, ball joints) built twice from one list of
joints: as eomgen's model (:func:`eomgen.model.build_model`, which expands each ball joint, and
:func:`eomgen.model.floating.add_free_flyer`) and as Pinocchio's, by hand
(``pin.Model.addJoint`` with ``JointModelFreeFlyer``, ``JointModelSpherical`` and unaligned
revolute or prismatic joints), so that the same arrays q (NQ) and v (NV) feed both.
"""

from __future__ import annotations

import numpy as np

from eomgen.model import Joint, JointType, Link, Transform, build_model, mat3, vec3

from .reference import random_inertial, random_rotation

KINDS = {"revolute": JointType.REVOLUTE, "prismatic": JointType.PRISMATIC,
         "spherical": JointType.SPHERICAL}
GRAVITY = (0.3, -0.2, -9.81)

#: A floating trunk with a ball hip, a revolute knee below it and a revolute arm:
#: (name, type, parent joint index or -1 for the trunk); names sort in depth-first order.
TWO_LEGS = (("a_hip", "spherical", -1), ("b_knee", "revolute", 0), ("c_arm", "revolute", -1))
#: A fixed-base chain: a revolute joint, a ball joint, a prismatic joint.
BALL_CHAIN = (("j0", "revolute", -1), ("ball", "spherical", 0), ("j2", "prismatic", 1))


#: A hopper in eomgen's YAML: a trunk, a ball hip, a revolute knee (``HOPPER_SCENE`` lets the
#: trunk fly on the quaternion free flyer and gives the knee a drive: armature, viscous and
#: Coulomb friction).
HOPPER = """name: hopper
links:
  - {name: trunk, mass: 3.0, com: [0.02, -0.01, 0.05],
     inertia: {ixx: 0.05, iyy: 0.06, izz: 0.04, ixy: 0.002}}
  - {name: thigh, mass: 1.0, com: [0.0, 0.01, -0.15], inertia: {ixx: 0.02, iyy: 0.021, izz: 0.004}}
  - {name: shin, mass: 0.6, com: [0.01, 0.0, -0.12], inertia: {ixx: 0.01, iyy: 0.011, izz: 0.002}}
joints:
  - {name: hip, type: spherical, parent: trunk, child: thigh, origin: {xyz: [0.1, 0.0, -0.05]}}
  - {name: knee, type: revolute, parent: thigh, child: shin, origin: {xyz: [0.0, 0.0, -0.3]},
     axis: [0, 1, 0]}
"""
HOPPER_SCENE = """version: 1
floating_base: quaternion
actuators:
  knee: {armature: 0.05, damping: 0.3, friction: 0.4}
"""


def pin_inertia(pin, inertial):
    return pin.Inertia(float(inertial.mass), np.array([float(x) for x in inertial.com]),
                       np.array([[float(x) for x in row] for row in inertial.inertia]))


def quaternion_robot(spec, seed: int = 0, free_flyer: bool = False, actuators=None,
                     name: str = "quat"):
    """``(eomgen model, Pinocchio model)`` of ``spec`` (see :data:`TWO_LEGS`): random joint
    placements, axes and inertias (every link with mass), gravity :data:`GRAVITY`;
    ``actuators`` maps joint names to :class:`~eomgen.model.Actuator` (Pinocchio's model gets
    their armature in ``model.armature``)."""
    import pinocchio as pin
    from eomgen.model.floating import add_free_flyer

    actuators = actuators or {}
    rng = np.random.default_rng(seed)
    root_inertia = random_inertial(rng)
    links, joints = [Link("trunk", root_inertia)], []
    pm = pin.Model()
    parent_id = 0
    if free_flyer:
        parent_id = pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
        pm.appendBodyToJoint(parent_id, pin_inertia(pin, root_inertia), pin.SE3.Identity())
    ids = []
    for joint_name, kind, parent in spec:
        R, p = random_rotation(rng), rng.uniform(-0.5, 0.5, 3)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        inertial = random_inertial(rng)
        links.append(Link(f"link_{joint_name}", inertial))
        joints.append(Joint(joint_name, KINDS[kind],
                            "trunk" if parent < 0 else f"link_{spec[parent][0]}",
                            f"link_{joint_name}", Transform(mat3(R.tolist()), vec3(p.tolist())),
                            vec3(axis.tolist()), actuator=actuators.get(joint_name)))
        joint_model = {"revolute": pin.JointModelRevoluteUnaligned,
                       "spherical": pin.JointModelSpherical,
                       "prismatic": pin.JointModelPrismaticUnaligned}[kind]
        jid = pm.addJoint(parent_id if parent < 0 else ids[parent],
                          joint_model() if kind == "spherical" else joint_model(axis),
                          pin.SE3(R, p), joint_name)
        pm.appendBodyToJoint(jid, pin_inertia(pin, inertial), pin.SE3.Identity())
        pm.addBodyFrame(f"link_{joint_name}", jid, pin.SE3.Identity(), 0)
        ids.append(jid)
    model = build_model("<test>", name, links, joints, gravity=list(GRAVITY))
    if free_flyer:
        model = add_free_flyer(model)
    pm.gravity = pin.Motion(np.array(GRAVITY), np.zeros(3))
    armature = np.zeros(pm.nv)
    for joint_name, actuator in actuators.items():
        armature[pm.joints[pm.getJointId(joint_name)].idx_v] = float(actuator.armature)
    pm.armature = armature
    return model, pm


def pinocchio_states(pm, count: int = 2, seed: int = 0):
    """``count`` random ``(q, v, a)``: Pinocchio's random configuration in [-1, 1] (unit
    quaternions), standard normal v and a."""
    import pinocchio as pin
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


def body_columns(model, pm) -> list[int]:
    """The columns of eomgen's regressor (10 per movable joint, ``PARAMETER_NAMES``) that
    hold Pinocchio's bodies, joint by joint in Pinocchio's order: a quaternion joint's body is
    the child of the last of its virtual joints (``base_wz``, ``<ball>_wz``)."""
    names = list(model.joint_names)
    out = []
    for name in pm.names[1:]:
        own = ("base_wz" if name == "root_joint" else f"{name}_wz" if f"{name}_wz" in names
               else name)
        out += range(10 * names.index(own), 10 * names.index(own) + 10)
    return out


def pinocchio_parameters(pm) -> np.ndarray:
    """π of Pinocchio's model: ``toDynamicParameters`` of every body, joint order."""
    return np.concatenate([pm.inertias[j].toDynamicParameters() for j in range(1, pm.njoints)])


__all__ = ["BALL_CHAIN", "GRAVITY", "HOPPER", "HOPPER_SCENE", "TWO_LEGS", "body_columns", "pinocchio_parameters",
           "pinocchio_states", "quaternion_robot"]
