"""``RobotModel.joint_places`` (every joint with its kind and its first entries in q and v), the
virtual base joint (``base_kind``) and the configuration-space queries of
:mod:`eomgen.model.configuration` that the algorithms use instead of naming a kind, checked
against what the model says independently: its ``JOINT_NAMES`` and ``CONFIGURATION_NAMES``
(the names each kind gives its entries), its sizes, and the norms computed here by hand.
"""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.model import Inertial, Joint, JointType, Link, build_model
from eomgen.model.configuration import (chart_indices, neutral, norm_error, quaternion_indices,
                                        random_configuration)
from eomgen.model.floating import add_floating_base, add_free_flyer
from eomgen.model.joints import KINDS

_I = Inertial(1.0, (0.1, 0.0, 0.0), [[0.1, 0, 0], [0, 0.2, 0], [0, 0, 0.3]])


def _mixed(float_with=add_free_flyer):
    """A trunk on ``float_with``, then a universal, a ball, a planar and a revolute joint."""
    links = [Link(name, _I) for name in ("trunk", "a", "b", "c", "d")]
    joints = [Joint("u", JointType.UNIVERSAL, "trunk", "a"),
              Joint("ball", JointType.SPHERICAL, "a", "b"),
              Joint("pl", JointType.PLANAR, "b", "c", axis=(0, 0, 1)),
              Joint("r", JointType.REVOLUTE, "c", "d", axis=(1, 0, 0))]
    return float_with(build_model("<memory>", "mixed", links, joints))


@pytest.fixture(scope="module")
def mixed():
    return _mixed()


def test_places_tile_q_and_v_with_the_names_each_kind_gives(mixed):
    places = mixed.joint_places
    assert [p.v_index for p in places] == list(np.cumsum([0] + [p.nv for p in places])[:-1])
    assert [p.q_index for p in places] == list(np.cumsum([0] + [p.nq for p in places])[:-1])
    assert sum(p.nv for p in places) == mixed.dof and sum(p.nq for p in places) == mixed.nq
    for p in places:
        assert mixed.joint_names[p.v_slice] == p.kind.velocity_names(p.name)
        assert mixed.configuration_names[p.q_slice] == p.kind.configuration_names(p.name)
    # one place per joint with a chart, in q and v order; a universal joint's chain is two
    # coordinates of the tree
    assert [(p.kind.name, p.name) for p in places] == [
        ("free_flyer", "base"), ("continuous", "u_rx"), ("continuous", "u_ry"),
        ("spherical", "ball"), ("planar", "pl"), ("revolute", "r")]
    assert tuple(p for p in places if p.nq != p.nv) == mixed.quaternion_joints


def test_the_virtual_base_joint_is_the_kind_marked_base(mixed):
    assert [name for name, kind in KINDS.items() if kind.base] == ["free_flyer"]
    assert mixed.base_kind is KINDS["free_flyer"] and mixed.free_flyer
    euler = _mixed(add_floating_base)  # six virtual joints: no base kind, q is v there
    assert euler.base_kind is None and not euler.free_flyer
    fixed = _mixed(lambda model: model)
    assert fixed.base_kind is None
    assert [p.kind.name for p in euler.joint_places[:6]] == ["prismatic"] * 3 + ["continuous"] * 3


def test_configuration_queries_against_the_entry_names_and_norms(mixed):
    names = mixed.configuration_names
    assert [names[k] for k in quaternion_indices(mixed)] == ["base_qx", "ball_qx"]
    massless, charted = chart_indices(mixed)
    # every virtual joint of a chart but its last carries a massless link; the charts'
    # velocities are the free flyer's, the ball's and the planar joint's
    assert massless == (0, 1, 2, 3, 4, 8, 9, 11, 12)
    assert charted == tuple(range(0, 6)) + tuple(range(8, 14))
    child = [mixed.link_by_name[j.child] for j in mixed.coordinate_joints]
    assert [k for k, link in enumerate(child) if link.inertial is None or
            float(link.inertial.mass) == 0.0] == sorted([*massless, 6])  # and the universal cross
    rng = np.random.default_rng(3)
    q = random_configuration(mixed, rng.normal(size=mixed.dof), rng)
    assert norm_error(q, mixed) < 1e-15 and norm_error(neutral(mixed), mixed) == 0.0
    q[9:13] *= 1.25  # the ball's quaternion off the sphere by 0.25 of its length
    assert norm_error(q, mixed) == pytest.approx(0.25, rel=1e-12)
    q[13 + 2:13 + 4] *= 0.5  # the planar joint's (cos, sin) at half its length
    assert norm_error(q, mixed) == pytest.approx(0.5, rel=1e-12)
