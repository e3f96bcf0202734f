"""Coupled joints on a model with quaternion joints (issue 26): a free flyer and a URDF
<mimic>, checked against Pinocchio's mimic model on a free flyer
(``buildModelFromUrdf(path, JointModelFreeFlyer(), mimic=True)``). The MJCF tests
(tests/parsers/test_mjcf_equalities.py) check a ball joint with a coupling against MuJoCo.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedError
from eomgen.model.floating import add_free_flyer
from eomgen.model import couple, uncoupled
from eomgen.model.coupling import full_configuration
from support import relative
from support.extras import need

pin = need("pinocchio", reason="checked against Pinocchio's mimic joints")

LINK = """  <link name="{name}"><inertial><origin xyz="{com}" rpy="0.1 0.2 0.3"/>
    <mass value="{mass}"/><inertia ixx="0.02" ixy="0.001" ixz="0.002" iyy="0.03" iyz="-0.001"
    izz="0.025"/></inertial></link>
"""
JOINT = """  <joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
    <origin xyz="{xyz}" rpy="0.2 -0.1 0.3"/><axis xyz="{axis}"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>{mimic}</joint>
"""


def urdf() -> str:
    """A floating torso with two legs: 'hip' and 'knee' on one, 'knee2' mimics 'knee' on the
    other (gain -0.7, offset 0.3), a prismatic 'slide' mimics 'hip' (gain 0.05)."""
    links = "".join(LINK.format(name=n, com=c, mass=m) for n, c, m in (
        ("torso", "0.01 -0.02 0.03", 4), ("thigh", "0 0.01 -0.2", 1.2),
        ("shin", "0.01 0 -0.2", 0.8), ("shin2", "0 -0.01 -0.15", 0.6),
        ("pad", "0.02 0 0", 0.2)))
    joints = "".join(JOINT.format(name=n, kind=k, parent=p, child=c, xyz=x, axis=a, mimic=mm)
                     for n, k, p, c, x, a, mm in (
        ("hip", "revolute", "torso", "thigh", "0.1 0.15 -0.1", "0 1 0", ""),
        ("knee", "revolute", "thigh", "shin", "0 0 -0.4", "1 0 0", ""),
        ("knee2", "revolute", "torso", "shin2", "-0.1 0.1 -0.1", "0 0.6 0.8",
         '<mimic joint="knee" multiplier="-0.7" offset="0.3"/>'),
        ("slide", "prismatic", "shin", "pad", "0 0 -0.3", "1 0 0",
         '<mimic joint="hip" multiplier="0.05" offset="0.01"/>')))
    return f'<?xml version="1.0"?>\n<robot name="mimic_flyer">\n{links}{joints}</robot>\n'


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    path = tmp_path_factory.mktemp("mimic") / "mimic_flyer.urdf"
    path.write_text(urdf(), encoding="utf-8")
    model = add_free_flyer(eomgen.load(path))
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer(), mimic=True)
    module = eomgen.derive(model, ("M", "C", "g", "tau", "h")).lambdify().module
    return model, pm, module


def test_followers_leave_the_coordinates(case):
    model, pm, _ = case
    assert (model.nq, model.dof) == (pm.nq, pm.nv) == (9, 8)
    assert model.joint_names[6:] == ("hip", "knee")
    assert model.configuration_names[:7] == ("base_x", "base_y", "base_z", "base_qx", "base_qy",
                                             "base_qz", "base_qw")


def test_dynamics_equal_pinocchio_mimic_on_a_free_flyer(case):
    model, pm, module = case
    data = pm.createData()
    hip, knee = pm.idx_qs[pm.getJointId("hip")], pm.idx_qs[pm.getJointId("knee")]
    rng = np.random.default_rng(7)
    for _ in range(3):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        v, a = rng.normal(size=(2, pm.nv))
        ours = np.concatenate([q[:7], [q[hip], q[knee]]])  # Pinocchio's order may differ
        ov = np.concatenate([v[:6], [v[pm.idx_vs[pm.getJointId("hip")]],
                                     v[pm.idx_vs[pm.getJointId("knee")]]]])
        oa = np.concatenate([a[:6], [a[pm.idx_vs[pm.getJointId("hip")]],
                                     a[pm.idx_vs[pm.getJointId("knee")]]]])
        order = [*range(6), pm.idx_vs[pm.getJointId("hip")], pm.idx_vs[pm.getJointId("knee")]]
        M = pin.crba(pm, data, q)
        M = (np.triu(M) + np.triu(M, 1).T)[np.ix_(order, order)]
        h = pin.nonLinearEffects(pm, data, q, v)[order]
        g = pin.computeGeneralizedGravity(pm, data, q)[order]
        tau = pin.rnea(pm, data, q, v, a)[order]
        assert relative(module.mass_matrix(ours).reshape(M.shape), M) < 1e-10
        assert relative(module.nonlinear_effects(ours, ov).ravel(), h) < 1e-10
        assert relative(module.gravity_vector(ours).ravel(), g) < 1e-10
        assert relative(module.inverse_dynamics(ours, ov, oa).ravel(), tau) < 1e-10
        C = module.coriolis_matrix(ours, ov).reshape(M.shape)
        assert relative(C @ ov + g, h) < 1e-10


def test_coriolis_is_skew_compatible(case):
    """Ṁ − 2C skew-symmetric (Ṁ by a central difference along the motion of q)."""
    from eomgen.model.floating import integrate
    model, _, module = case
    rng = np.random.default_rng(3)
    q = rng.uniform(-1, 1, model.nq)
    q[3:7] /= np.linalg.norm(q[3:7])
    v, eps = rng.normal(size=model.dof), 1e-6
    dM = (module.mass_matrix(integrate(q, v * eps, model=model))
          - module.mass_matrix(integrate(q, -v * eps, model=model))).reshape(8, 8) / (2 * eps)
    N = dM - 2 * module.coriolis_matrix(q, v).reshape(8, 8)
    assert np.abs(N + N.T).max() < 1e-6 * max(1.0, np.abs(dM).max())


def test_full_configuration_copies_the_quaternion_and_couples_the_followers(case):
    model = case[0]
    q = np.arange(1.0, 10.0)
    full = full_configuration(model, q)
    names = uncoupled(model).configuration_names
    assert len(full) == uncoupled(model).nq == 11
    assert list(full[:7]) == list(q[:7])
    by = dict(zip(names, full))
    assert by["hip"] == q[7] and by["knee"] == q[8]
    assert by["knee2"] == pytest.approx(-0.7 * q[8] + 0.3)
    assert by["slide"] == pytest.approx(0.05 * q[7] + 0.01)


def test_coupling_a_virtual_joint_is_refused(case):
    model = case[0]
    with pytest.raises(UnsupportedError, match="virtual joint of free flyer joint .base.: only one-axis joints"):
        couple(model, "hip", "base_wz")
