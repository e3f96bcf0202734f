"""The Slotine–Li, base Slotine–Li and energy regressors of models with quaternion joints (a
free flyer with a driven leg, a fixed-base chain through a ball joint) against Pinocchio's
models built by hand (``JointModelFreeFlyer``, ``JointModelSpherical``, ``model.armature``),
the arrays q (NQ) and v, v_r, a_r (NV) passed unchanged:

* Y_SL(q, v, v_r, a_r) π = M a_r + C(q, v) v_r + g + d v_r + f sign(v), with Pinocchio's
  ``crba`` (armature included), ``computeCoriolisMatrix``, ``computeGeneralizedGravity``;
* Y_SL(q, v, v, a) is the joint torque regressor, and in the real bodies' columns Pinocchio's
  ``computeJointTorqueRegressor``; Y_SL_base β = Y_SL π;
* Y_K π and Y_P π are Pinocchio's kinetic and potential energies, and their real bodies'
  columns Pinocchio's energy regressors.
"""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.model import Actuator
from support import relative
from support.generated import generated
from support.quaternion import (body_columns, pinocchio_parameters, pinocchio_states,
                                quaternion_robot)
from support.extras import need

pin = need("pinocchio", reason="quaternion joints are checked against Pinocchio")

FUNCTIONS = ("Y_SL", "Y_SL_base", "Y", "pi", "beta", "Y_K", "Y_P")
KNEE = Actuator(armature=0.3, damping=0.4, friction=0.2, friction_width=0.5)
CASES = {
    # a free flyer whose trunk carries one driven revolute leg
    "free_flyer": ((("knee", "revolute", -1),), True, {"knee": KNEE}),
    # a fixed base, a ball joint, a driven revolute joint below it
    "ball": ((("a_ball", "spherical", -1), ("b_elbow", "revolute", 0)), False,
             {"b_elbow": KNEE}),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request, tmp_path_factory):
    spec, free_flyer, drives = CASES[request.param]
    model, pm = quaternion_robot(spec, seed=4, free_flyer=free_flyer, actuators=drives)
    calls, _ = generated(model, FUNCTIONS, tmp_path_factory.mktemp(request.param),
                         backends=("numpy",))
    viscous, coulomb = np.zeros(pm.nv), np.zeros(pm.nv)
    for name, drive in drives.items():
        k = pm.joints[pm.getJointId(name)].idx_v
        viscous[k], coulomb[k] = drive.damping, drive.friction
    return model, pm, calls["numpy"], viscous, coulomb


def test_slotine_li_regressor_is_pinocchios_M_C_g(case):
    model, pm, call, viscous, coulomb = case
    data = pm.createData()
    pi, beta = call("inertial_parameters"), call("base_parameters")
    rng = np.random.default_rng(7)
    assert pm.armature.any()
    for q, v, a in pinocchio_states(pm, count=2, seed=1):
        v_r, a_r = rng.normal(size=pm.nv), rng.normal(size=pm.nv)
        M = pin.crba(pm, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        C = pin.computeCoriolisMatrix(pm, data, q, v).copy()
        g = pin.computeGeneralizedGravity(pm, data, q).copy()
        expected = M @ a_r + C @ v_r + g + viscous * v_r + coulomb * np.sign(v)
        Y_SL = call("slotine_li_regressor", q, v, v_r, a_r)
        assert Y_SL.shape == (pm.nv, len(pi))
        assert relative(Y_SL @ pi, expected) < 1e-12
        assert relative(call("slotine_li_base_regressor", q, v, v_r, a_r) @ beta,
                        expected) < 1e-12
        # with the robot's own velocity and acceleration: the joint torque regressor
        own = call("slotine_li_regressor", q, v, v, a)
        assert relative(own, call("regressor", q, v, a)) < 1e-12
        reference = pin.computeJointTorqueRegressor(pm, data, q, v, a)
        assert relative(own[:, body_columns(model, pm)], reference) < 1e-12


def test_energy_regressors_are_pinocchios_energies(case):
    model, pm, call, _, _ = case
    data = pm.createData()
    pi, columns = call("inertial_parameters"), body_columns(model, pm)
    assert relative(pi[columns], pinocchio_parameters(pm)) < 1e-14
    for q, v, _ in pinocchio_states(pm, count=2, seed=2):
        Y_K, Y_P = call("kinetic_energy_regressor", q, v), call("potential_energy_regressor", q)
        assert relative(Y_K @ pi, pin.computeKineticEnergy(pm, data, q, v)) < 1e-12
        assert relative(Y_P @ pi, pin.computePotentialEnergy(pm, data, q)) < 1e-12
        assert relative(Y_K[columns], pin.computeKineticEnergyRegressor(pm, data, q, v)) < 1e-12
        assert relative(Y_P[columns], pin.computePotentialEnergyRegressor(pm, data, q)) < 1e-12
