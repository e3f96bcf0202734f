"""Adapters to Pinocchio (optional: ``pip install pin``; importing this module does not import it).

* :func:`to_pinocchio` builds a ``pinocchio.Model`` from a :class:`~eomgen.model.RobotModel`,
  joint by joint (:class:`PinocchioModel`, in eomgen's joint order), and :func:`plain_calls`
  gives its dynamics as a user would call them (the benchmark's Pinocchio route).
* :class:`~eomgen.numeric.floating_base.PinocchioFreeFlyer` (importable here too) reads a URDF
  with Pinocchio's own free flyer and evaluates it in eomgen's Euler coordinates.

Building from the model rather than from URDF text means every input eomgen reads (URDF, DH
tables, eomgen YAML, scenes, locked joints) gets the same Pinocchio model, and a continuous
joint stays one coordinate (Pinocchio's URDF reader gives it two: cos and sin).

* Every movable joint becomes ``JointModelRevoluteUnaligned`` / ``JointModelPrismaticUnaligned``
  about its axis, placed at the composite of the fixed transforms from its last movable
  ancestor (or the root) to its origin; the virtual joints of a quaternion joint
  (:mod:`eomgen.model.quaternion`) become one ``JointModelFreeFlyer`` (named ``root_joint``)
  or ``JointModelSpherical`` (named as the ball joint), so that ``q`` (NQ) and ``v`` (NV) are
  Pinocchio's arrays.
* Every link's inertia is appended to the Pinocchio joint it moves with, at the composite
  placement; links fixed to the root do not move and are left out.
* Joints are numbered in depth-first preorder (Pinocchio's CRBA assumes every subtree is a
  contiguous range); :class:`PinocchioModel` maps coordinates to eomgen's ``JOINT_NAMES`` order
  (``perm``, and ``qperm`` for the configuration when NQ ≠ NV).
* Gravity is the model's, in the root frame; parameters take their values.
* Coupled joints (a URDF ``<mimic>``, :mod:`eomgen.model.coupling`): the Pinocchio model is the
  whole tree's (every movable joint, followers included), and :class:`PinocchioModel` maps the
  independent coordinates to it (``q_tree = T q + c``, ``v_tree = T v``) and projects
  (``Tᵀ τ``, ``Tᵀ M T``), as eomgen's reduced model does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import RobotModel, coupling_map, uncoupled
# PinocchioFreeFlyer lives with the Euler maps it uses; importable here too.
from .floating_base import PinocchioFreeFlyer  # noqa: F401
from .model import configuration_map

__all__ = ["PinocchioModel", "to_pinocchio", "plain_calls", "pinocchio_name"]


def _floats(v) -> np.ndarray:
    return np.array([float(x) for x in v], dtype=float)


def _matrix(m) -> np.ndarray:
    return np.array([[float(x) for x in row] for row in m], dtype=float)


@dataclass(frozen=True)
class PinocchioModel:
    """A Pinocchio model and data of a robot, in eomgen's joint order.

    Attributes
    ----------
    model, data:
        ``pinocchio.Model`` and ``pinocchio.Data``.
    perm:
        (n,) ints: Pinocchio's coordinate k is eomgen's ``perm[k]`` (``q_pin = q[perm]``).
    qperm:
        (nq,) ints, the same for the configuration (``q_pin = q[qperm]``); None: ``perm``.
    coupling:
        ``(T, P, c_q)`` of the model's coupled joints (float arrays: ``v_tree = T v``,
        ``q_tree = P q + c_q``, :func:`eomgen.numeric.model.configuration_map`), in whose
        whole-tree coordinates ``perm`` is given; None without couplings.
    """

    model: object
    data: object
    perm: np.ndarray
    qperm: np.ndarray | None = None
    coupling: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def identity(self) -> bool:
        """True when Pinocchio's arrays are eomgen's (same order)."""
        q = self.perm if self.qperm is None else self.qperm
        return (self.coupling is None and np.array_equal(self.perm, np.arange(len(self.perm)))
                and np.array_equal(q, np.arange(len(q))))

    def rnea(self, q, qd, qdd) -> np.ndarray:
        """τ (n,) in eomgen's order, by ``pinocchio.rnea``."""
        import pinocchio as pin  # optional dependency: imported when used

        p = self.perm
        q, qd, qdd = (np.asarray(x, float) for x in (q, qd, qdd))
        if self.coupling is not None:
            T, P, c = self.coupling
            q, qd, qdd = P @ q + c, T @ qd, T @ qdd
        tau = np.empty(len(p))
        qp = p if self.qperm is None else self.qperm
        tau[p] = pin.rnea(self.model, self.data, q[qp], qd[p], qdd[p])
        return tau if self.coupling is None else self.coupling[0].T @ tau

    def crba(self, q) -> np.ndarray:
        """M (n, n) in eomgen's order, by ``pinocchio.crba`` (upper triangle mirrored)."""
        import pinocchio as pin  # optional dependency: imported when used

        p = self.perm
        q = np.asarray(q, float)
        if self.coupling is not None:
            q = self.coupling[1] @ q + self.coupling[2]
        qp = p if self.qperm is None else self.qperm
        upper = np.triu(pin.crba(self.model, self.data, q[qp]))
        M_pin = upper + np.triu(upper, 1).T
        inverse = np.argsort(p)
        M = M_pin[np.ix_(inverse, inverse)]
        return M if self.coupling is None else self.coupling[0].T @ M @ self.coupling[0]


def to_pinocchio(model: RobotModel) -> PinocchioModel:
    """Build the Pinocchio model of ``model`` (see the module docstring).

    Raises
    ------
    ImportError
        When Pinocchio is not installed.
    """
    import pinocchio as pin  # optional dependency: imported when used

    if model.free_symbols:
        model = model.with_numeric_parameters()
    coupling = None
    if model.couplings:
        coupling = (_matrix(coupling_map(model)[0].tolist()), *configuration_map(model))
        model = uncoupled(model)
    pmodel = pin.Model()
    pmodel.name = model.name
    anchor = {model.root: (0, pin.SE3.Identity())}  # link -> (joint id, placement in it)
    chains = {model.movable_joints[p.v_index].name: p for p in model.joint_places if p.nq != p.nv}
    inside: dict[str, int] = {}  # a quaternion joint's later virtual joints -> its Pinocchio id
    for joint in model.topological_joints:  # depth-first preorder
        parent_id, placement = anchor[joint.parent]
        T = placement * pin.SE3(_matrix(joint.origin.rotation), _floats(joint.origin.translation))
        if joint.name in inside:
            anchor[joint.child] = (inside[joint.name], pin.SE3.Identity())
        elif joint.name in chains:
            q_joint = chains[joint.name]
            jid = pmodel.addJoint(parent_id, getattr(pin, q_joint.kind.pinocchio)(), T,
                                  pinocchio_name(q_joint))
            anchor[joint.child] = (jid, pin.SE3.Identity())
            for later in model.movable_joints[q_joint.v_index + 1:q_joint.v_index + q_joint.nv]:
                inside[later.name] = jid
        elif joint.type.is_movable:
            axis = _floats(joint.axis)
            kind = (pin.JointModelHelicalUnaligned(axis, float(joint.pitch))
                    if joint.rotates and joint.type.kind.translates
                    else pin.JointModelRevoluteUnaligned(axis) if joint.rotates
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
    places = {pinocchio_name(p): p for p in model.joint_places}
    perm, qperm = np.empty(pmodel.nv, dtype=int), np.empty(pmodel.nq, dtype=int)
    for jid in range(1, pmodel.njoints):
        name, pj = pmodel.names[jid], pmodel.joints[jid]
        v0, q0 = places[name].v_index, places[name].q_index
        perm[pj.idx_v:pj.idx_v + pj.nv] = np.arange(v0, v0 + pj.nv)
        qperm[pj.idx_q:pj.idx_q + pj.nq] = np.arange(q0, q0 + pj.nq)
    return PinocchioModel(pmodel, pmodel.createData(), perm,
                          None if np.array_equal(perm, qperm) else qperm, coupling)


def pinocchio_name(joint) -> str:
    """The name of a joint (a place of :attr:`~eomgen.model.RobotModel.joint_places`) in the
    Pinocchio model: ``root_joint`` for a virtual base joint (the free flyer, as Pinocchio's
    URDF reader names it), the joint's own name otherwise."""
    return "root_joint" if joint.kind.base else joint.name


def plain_calls(pm: PinocchioModel, n: int):
    """``(rnea, crba, note)``: Pinocchio's dynamics as a user would call it on ``pm``, for timing.

    Where Pinocchio's joint order is eomgen's, the plain public calls ``pin.rnea(model, data,
    q, qd, qdd)`` and ``pin.crba(model, data, q)`` (which from Python returns the whole
    symmetric M), on arrays already in Pinocchio's order; otherwise :meth:`PinocchioModel.rnea`
    and :meth:`~PinocchioModel.crba`, the reordering a user of this model would need, and the
    note says so."""
    import pinocchio as pin  # optional dependency: imported when used

    model, data = pm.model, pm.data
    if pm.identity:
        return (lambda q, qd, qdd: pin.rnea(model, data, q, qd, qdd),
                lambda q: pin.crba(model, data, q),
                f"pinocchio {pin.__version__}: plain pin.rnea and pin.crba calls")
    if pm.coupling is not None:
        return (pm.rnea, pm.crba,
                f"pinocchio {pin.__version__}: pin.rnea and pin.crba on the whole tree at "
                "q = T q_r + c, projected by Tᵀ (the coupling map a user of this model needs)")
    return (pm.rnea, pm.crba,
            f"pinocchio {pin.__version__}: pin.rnea and pin.crba with the joints "
            "reordered to eomgen's order (a conversion a user of this model needs)")
