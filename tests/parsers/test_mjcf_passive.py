"""The passive forces of MJCF models (joint springs, the drives' damping, fixed tendons:
eomgen.symbolic.passive, ``passive_forces``) against MuJoCo's ``qfrc_passive`` at random states,
mapped to eomgen's coordinates by eomgen.parsers.mjcf.convert; and the forward dynamics they
make, M_a⁻¹ (τ_p − h), against MuJoCo's ``qacc_smooth`` (no actuators, contacts disabled).

The models: two written here (hinge and slide springs with refs, a fixed tendon with a dead
band and damping, one with a single rest length; a free body with springs and a tendon
below it), and gymnasium's hopper and ant (tests/data/mjcf/gymnasium, MIT), whose MuJoCo
passive forces are the joints' damping and springs.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedFeatureWarning
from support import model_states, relative
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import compile_mjcf  # noqa: E402
from eomgen.parsers.mjcf.convert import layout, mujoco_dynamics, to_mujoco  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "data" / "mjcf"
TOLERANCE = 1e-10

CHAIN = """<mujoco model="springs"><option><flag contact="disable"/></option><worldbody>
<body><joint name="a" axis="0 1 0" stiffness="3" springref="20" damping="0.4"/>
 <geom type="capsule" size=".05" fromto="0 0 0 0 0 -.5"/>
 <body pos="0 0 -.5"><joint name="b" type="slide" axis="1 0 0" stiffness="5" springref="0.1"
   ref="0.05"/><geom size=".1"/>
  <body pos="0 0 -.3"><joint name="c" axis="1 0 0" ref="10" armature="0.02"/>
   <geom type="capsule" size=".05" fromto="0 0 0 0 0 -.3"/></body>
 </body></body></worldbody>
<tendon><fixed name="band" stiffness="2" springlength="-0.4 0.6" damping="0.5">
 <joint joint="a" coef="1"/><joint joint="c" coef="-2"/></fixed>
<fixed name="rest" stiffness="7" springlength="0.2"><joint joint="b" coef="0.5"/></fixed>
<fixed name="damper" damping="1.5"><joint joint="a" coef="0.3"/><joint joint="b" coef="2"/>
</fixed></tendon></mujoco>"""

FLOATING = """<mujoco model="floating"><option><flag contact="disable"/></option><worldbody>
<body pos="0 0 1"><freejoint name="root"/><geom size=".2" mass="3"/>
 <body pos=".3 0 0"><joint name="h1" axis="0 0 1" stiffness="4" springref="-30" damping=".2"/>
  <geom type="capsule" size=".05" fromto="0 0 0 .4 0 0"/>
  <body pos=".4 0 0"><joint name="h2" axis="0 1 0" stiffness="1.5"/>
   <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/></body></body>
 <body pos="-.3 0 0"><joint name="s1" type="slide" axis="0 0 1" damping=".7"/>
  <geom size=".1"/></body></body></worldbody>
<tendon><fixed name="t" stiffness="3" damping=".3" springlength=".25">
 <joint joint="h1" coef="1"/><joint joint="s1" coef="-1.5"/></fixed></tendon></mujoco>"""


def quiet_load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)
        return eomgen.load(path)


@pytest.fixture(scope="module")
def derived(tmp_path_factory):
    """``{name: (model, compiled, module)}``, each derived once with tau_p, M_a and h."""
    folder = tmp_path_factory.mktemp("passive")
    paths = {"chain": folder / "chain.xml", "floating": folder / "floating.xml",
             "hopper": DATA / "gymnasium" / "hopper.xml", "ant": DATA / "gymnasium" / "ant.xml"}
    paths["chain"].write_text(CHAIN)
    paths["floating"].write_text(FLOATING)
    out = {}
    for name, path in paths.items():
        model = quiet_load(path)
        out[name] = (model, compile_mjcf(path),
                     eomgen.derive(model, outputs=("tau_p", "M_a", "h")).lambdify().module)
    return out


def test_the_model_holds_the_springs_and_tendons(derived):
    model = derived["chain"][0]
    springs = {j.name: j.spring for j in model.joints if j.spring is not None}
    assert set(springs) == {"a", "b"}
    assert float(springs["a"].stiffness) == 3
    assert float(springs["a"].reference) == pytest.approx(np.radians(20))
    assert [t.name for t in model.tendons] == ["band", "rest", "damper"]
    assert tuple(float(v) for v in model.tendons[0].lengths) == (-0.4, 0.6)


@pytest.mark.parametrize("name", ["chain", "floating", "hopper", "ant"])
def test_passive_forces_are_mujocos(derived, name):
    model, m, module = derived[name]
    lay = layout(m, model)
    inside = outside = 0
    for q, v in model_states(model, count=8):
        ref = mujoco_dynamics(m, lay, q, v)
        tau_p = module.passive_forces(q, v).ravel()
        assert relative(tau_p, ref["passive"]) < TOLERANCE
        if name == "chain":  # the dead band of "band" is met on both sides
            length = q[0] - 2 * q[2]
            inside += -0.4 <= length <= 0.6
            outside += not -0.4 <= length <= 0.6
    assert name != "chain" or (inside and outside)


@pytest.mark.parametrize("name", ["chain", "floating"])
def test_forward_dynamics_with_passive_forces_is_mujocos(derived, name):
    """M_a q̈ = τ_p − h at τ = 0 is MuJoCo's qacc_smooth (no actuators, no contacts)."""
    model, m, module = derived[name]
    lay = layout(m, model)
    data = mujoco.MjData(m)
    for q, v in model_states(model, count=3):
        data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
        mujoco.mj_forward(m, data)
        qdd = np.linalg.solve(module.drive_mass_matrix(q),
                              module.passive_forces(q, v).ravel()
                              - module.nonlinear_effects(q, v).ravel())
        expected = np.linalg.lstsq(lay_velocity(lay, data.qpos), data.qacc_smooth
                                   - drift(lay, data.qpos, v), rcond=None)[0]
        assert relative(qdd, expected) < 1e-9


def lay_velocity(lay, qpos):
    from eomgen.parsers.mjcf.convert import velocity_map
    return velocity_map(lay, qpos)


def drift(lay, qpos, v):
    """``Ṫ v`` of the free joint (MuJoCo's qacc = T v̇ + Ṫ v)."""
    from eomgen.parsers.mjcf.tree import rotation_of_quaternion
    out = np.zeros(lay.nv)
    if lay.free is not None:
        qa, da = lay.free
        out[da:da + 3] = rotation_of_quaternion(qpos[qa + 3:qa + 7]) @ np.cross(v[3:6], v[0:3])
    return out


@pytest.mark.parametrize("name", ["half_cheetah", "hopper", "humanoid"])
def test_gymnasium_models_passive_forces_are_mujocos(name):
    """gymnasium's own assets (the ``mjcf-models`` extra): half_cheetah's 6 and the humanoid's
    14 joint springs, every joint's damping."""
    gymnasium = need("gymnasium", reason="gymnasium ships the MuJoCo models")
    path = Path(gymnasium.__file__).parent / "envs" / "mujoco" / "assets" / f"{name}.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the compiler's deprecations, motors on the free joint
        model = eomgen.load(path)
        m = compile_mjcf(path)
    assert sum(j.spring is not None for j in model.joints) == {
        "half_cheetah": 6, "hopper": 0, "humanoid": 14}[name]
    module = eomgen.derive(model, outputs=("tau_p",)).lambdify().module
    lay = layout(m, model)
    for q, v in model_states(model, count=4):
        ref = mujoco_dynamics(m, lay, q, v)["passive"]
        assert np.abs(ref).max() > 0
        assert relative(module.passive_forces(q, v).ravel(), ref) < TOLERANCE


TENDON_EQUALITY = """<mujoco model="teq"><worldbody>
<body><joint name="j1" axis="0 1 0" ref="5"/><geom size=".1"/>
 <body pos=".3 0 0"><joint name="j2" axis="0 1 0"/><geom size=".1"/>
  <body pos=".3 0 0"><joint name="j3" type="slide" axis="1 0 0"/><geom size=".1"/>
  </body></body></body></worldbody>
<tendon><fixed name="t1"><joint joint="j1" coef="2"/><joint joint="j2" coef="-1"/></fixed>
<fixed name="t2"><joint joint="j3" coef="0.5"/><joint joint="j2" coef="1"/></fixed></tendon>
<equality><tendon tendon1="t1" tendon2="t2" polycoef="0.1 1.5 0 0 0"/></equality></mujoco>"""


def test_a_tendon_equality_is_a_coupling_mujoco_holds(tmp_path):
    """At eomgen's states (the follower where the coupling puts it), MuJoCo's own tendon
    lengths satisfy L1 − L1_0 = c0 + c1 (L2 − L2_0)."""
    path = tmp_path / "teq.xml"
    path.write_text(TENDON_EQUALITY)
    model = quiet_load(path)
    m = compile_mjcf(path)
    assert [c.follower for c in model.couplings] == ["j1"]
    assert model.joint_names == ("j2", "j3")
    lay = layout(m, model)
    data = mujoco.MjData(m)
    for q, v in model_states(model, count=3):
        data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
        mujoco.mj_forward(m, data)
        L, L0 = data.ten_length, m.tendon_length0
        assert abs(L[0] - L0[0] - 0.1 - 1.5 * (L[1] - L0[1])) < 1e-12
        assert abs(data.ten_velocity[0] - 1.5 * data.ten_velocity[1]) < 1e-12
