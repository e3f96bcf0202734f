"""Each joint kind of eomgen.model.joints.KINDS on its own against Pinocchio's joint model of the
same kind (its ``pinocchio`` class, in a model of that one joint at the identity placement):
the pose ``transform(axis, q, pitch)`` against the joint data's ``M``, ``motion_subspace``
against its ``S``, the sizes, and ``neutral``, ``integrate``, ``difference`` and
``configuration_rate`` against the model's ``neutral``, ``integrate``, ``difference`` (its
Lie group) and a central difference of ``integrate`` in time; random axes and configurations.

(The joint data comes from ``forwardKinematics`` of the one-joint model: ``jmodel.calc`` on a
data object of its own leaves ``M`` unset in Pinocchio's Python bindings.)
"""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.model.joints import KINDS, ChainKind, ChartKind
from support import relative
from support.extras import need

pin = need("pinocchio", reason="the joint kinds are checked against Pinocchio's joint models")

PITCH = 0.07
#: Every kind but the fixed one (no motion, no Pinocchio joint model).
CHECKED = sorted(name for name, kind in KINDS.items() if kind.pinocchio)


def test_every_kind_but_fixed_names_a_pinocchio_joint_model():
    assert sorted(set(KINDS) - set(CHECKED)) == ["fixed"]
    assert (KINDS["fixed"].nq, KINDS["fixed"].nv) == (0, 0)
    for name in CHECKED:
        assert hasattr(pin, KINDS[name].pinocchio), name


def one_joint(kind, axis):
    """Pinocchio's model holding one joint of ``kind`` (about ``axis``, with :data:`PITCH`; a
    chain whose configuration is its coordinates, a universal joint: about its chain's axes)."""
    cls = getattr(pin, kind.pinocchio)
    if isinstance(kind, ChainKind) and not isinstance(kind, ChartKind):
        joint = cls(*(np.array(axis, dtype=float) for _, _, axis in kind.chain()))
    elif kind.rotates and kind.translates:
        joint = cls(axis, PITCH)
    elif kind.rotates or kind.translates:
        joint = cls(axis)
    else:
        joint = cls()
    pm = pin.Model()
    pm.addJoint(0, joint, pin.SE3.Identity(), "joint")
    return pm


@pytest.fixture(params=CHECKED)
def kind(request):
    rng = np.random.default_rng(sorted(KINDS).index(request.param))
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    kind = KINDS[request.param]
    return kind, axis, one_joint(kind, axis), rng


def configurations(pm, count=3):
    """Pinocchio's random configurations (translations in ±1, angles anywhere)."""
    return [pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq)) for _ in range(count)]


def test_sizes_and_neutral(kind):
    kind, _, pm, _ = kind
    assert (kind.nq, kind.nv) == (pm.nq, pm.nv)
    assert np.array_equal(kind.neutral(), pin.neutral(pm))


def test_transform_and_motion_subspace_are_the_joint_datas(kind):
    kind, axis, pm, _ = kind
    data = pm.createData()
    moved = 0.0
    for q in configurations(pm):
        pin.forwardKinematics(pm, data, q)
        jdata = data.joints[1]
        R, p = kind.transform(axis, q, PITCH)
        assert relative(R, jdata.M.rotation) < 1e-12
        if np.abs(jdata.M.translation).max() > 0:
            assert relative(p, jdata.M.translation) < 1e-12
        else:
            assert not np.abs(p).any()
        assert relative(kind.motion_subspace(axis, q, PITCH), np.asarray(jdata.S).reshape(6, pm.nv)) \
            < 1e-12
        moved = max(moved, np.abs(jdata.M.homogeneous - np.eye(4)).max())
    assert moved > 0.05  # the joint moved: the check is not at the identity


def _aligned(kind, q, reference):
    """``q`` with its quaternion's sign turned to ``reference``'s (q and −q: one rotation)."""
    q = np.array(q, dtype=float)
    k = getattr(kind, "quaternion_offset", None)  # a ChartKind's
    if k is not None and q[k:k + 4] @ reference[k:k + 4] < 0:
        q[k:k + 4] *= -1
    return q


def test_integrate_difference_and_rate_are_the_lie_groups(kind):
    kind, _, pm, rng = kind
    q0s, q1s = configurations(pm), configurations(pm)
    for q0, q1 in zip(q0s, q1s):
        v = rng.normal(size=pm.nv)
        reference = pin.integrate(pm, q0, v)
        assert relative(_aligned(kind, kind.integrate(q0, v), reference), reference) < 1e-12
        assert relative(kind.difference(q0, q1), pin.difference(pm, q0, q1)) < 1e-10
        h = 1e-6
        rate = (pin.integrate(pm, q0, h * v) - pin.integrate(pm, q0, -h * v)) / (2 * h)
        assert relative(kind.configuration_rate(q0, v), rate) < 1e-8
