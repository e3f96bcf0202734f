"""A ``pinocchio.Model`` built from a :class:`~eomgen.model.RobotModel`, joint by joint.

Building from the model rather than from URDF text means every input eomgen reads (URDF, DH
tables, eomgen YAML, scenes, locked joints) gets the same Pinocchio model, and a continuous
joint stays one coordinate (Pinocchio's URDF reader gives it two: cos and sin).

* Every movable joint becomes ``JointModelRevoluteUnaligned`` / ``JointModelPrismaticUnaligned``
  about its axis, placed at the composite of the fixed transforms from its last movable
  ancestor (or the root) to its origin.
* Every link's inertia is appended to the Pinocchio joint it moves with, at the composite
  placement; links fixed to the root do not move and are left out.
* Joints are numbered in depth-first preorder (Pinocchio's CRBA assumes every subtree is a
  contiguous range); :class:`PinocchioModel` maps coordinates to eomgen's ``JOINT_NAMES`` order.
* Gravity is the model's, in the root frame; parameters take their values.

Pinocchio is optional (``pip install pin``); importing this module does not import it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import Joint, RobotModel


def _floats(v) -> np.ndarray:
    return np.array([float(x) for x in v], dtype=float)


def _matrix(m) -> np.ndarray:
    return np.array([[float(x) for x in row] for row in m], dtype=float)


def _depth_first(model: RobotModel) -> list[Joint]:
    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint)
    order: list[Joint] = []
    stack = list(reversed(children.get(model.root, [])))
    while stack:
        joint = stack.pop()
        order.append(joint)
        stack.extend(reversed(children.get(joint.child, [])))
    return order


@dataclass(frozen=True)
class PinocchioModel:
    """A Pinocchio model and data of a robot, in eomgen's joint order.

    Attributes
    ----------
    model, data:
        ``pinocchio.Model`` and ``pinocchio.Data``.
    perm:
        (n,) ints: Pinocchio's coordinate k is eomgen's ``perm[k]`` (``q_pin = q[perm]``).
    """

    model: object
    data: object
    perm: np.ndarray

    def rnea(self, q, qd, qdd) -> np.ndarray:
        """τ (n,) in eomgen's order, by ``pinocchio.rnea``."""
        import pinocchio as pin

        p = self.perm
        tau = np.empty(len(p))
        tau[p] = pin.rnea(self.model, self.data, np.asarray(q, float)[p],
                          np.asarray(qd, float)[p], np.asarray(qdd, float)[p])
        return tau

    def crba(self, q) -> np.ndarray:
        """M (n, n) in eomgen's order, by ``pinocchio.crba`` (upper triangle mirrored)."""
        import pinocchio as pin

        p = self.perm
        upper = np.triu(pin.crba(self.model, self.data, np.asarray(q, float)[p]))
        M_pin = upper + np.triu(upper, 1).T
        inverse = np.argsort(p)
        return M_pin[np.ix_(inverse, inverse)]


def to_pinocchio(model: RobotModel) -> PinocchioModel:
    """Build the Pinocchio model of ``model`` (see the module docstring).

    Raises
    ------
    ImportError
        When Pinocchio is not installed.
    """
    import pinocchio as pin

    if model.free_symbols:
        model = model.with_numeric_parameters()
    pmodel = pin.Model()
    pmodel.name = model.name
    anchor = {model.root: (0, pin.SE3.Identity())}  # link -> (joint id, placement in it)
    for joint in _depth_first(model):
        parent_id, placement = anchor[joint.parent]
        T = placement * pin.SE3(_matrix(joint.origin.rotation), _floats(joint.origin.translation))
        if joint.type.is_movable:
            axis = _floats(joint.axis)
            kind = (pin.JointModelRevoluteUnaligned(axis) if joint.type.is_revolute
                    else pin.JointModelPrismaticUnaligned(axis))
            jid = pmodel.addJoint(parent_id, kind, T, joint.name)
            anchor[joint.child] = (jid, pin.SE3.Identity())
        else:
            anchor[joint.child] = (parent_id, T)
    for link in model.links:
        jid, T = anchor[link.name]
        if link.inertial is None or jid == 0:
            continue
        i = link.inertial
        inertia = pin.Inertia(float(i.mass), _floats(i.com), _matrix(i.inertia))
        pmodel.appendBodyToJoint(jid, inertia, T)
    pmodel.gravity = pin.Motion(_floats(model.gravity), np.zeros(3))
    ours = {name: k for k, name in enumerate(model.joint_names)}
    perm = np.empty(pmodel.nv, dtype=int)
    for jid in range(1, pmodel.njoints):
        perm[pmodel.joints[jid].idx_q] = ours[pmodel.names[jid]]
    return PinocchioModel(pmodel, pmodel.createData(), perm)
