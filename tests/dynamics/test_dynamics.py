"""Symbolic dynamics (:func:`eomgen.dynamics.derive`) against independent references.

* the textbook closed forms of the planar two-link arm, symbolically;
* Pinocchio (``crba``, ``computeCoriolisMatrix``, ``computeGeneralizedGravity``) on the arms of
  example-robot-data read by Pinocchio's own URDF reader, and on random chains and trees built
  joint by joint (``reference.to_pinocchio``);
* the definition of C from the Christoffel symbols, with ∂M/∂q by complex-step
  differentiation of the evaluated M;
* the structure of the result: outputs derived on demand, parameters kept symbolic, and the
  joint order of the description.

Numeric comparisons are relative: ``max|a − b| ≤ RTOL · max(1, max|b|)`` over all entries.
"""

from __future__ import annotations

import functools
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import eomgen
import support
from eomgen.dynamics import Dynamics, derive
from eomgen.errors import UnsupportedFeatureWarning
from eomgen.model import RobotModel, lock_joints, parameter_symbol
from eomgen.numeric import kinetic_energy, numeric_model, potential_energy
from eomgen.robots import example_path
from eomgen.symbolic.evaluate import compile_program
from support import assert_close, erd_robots_dir
from support.reference import random_robot, to_pinocchio
from support.extras import need

RTOL = 1e-10
_COMPILED: dict = {}
STATES = 3  # random states per robot for the numeric comparisons


def random_states(rng, n, count=STATES):
    """(q, qd) pairs."""
    return support.random_states(rng, n, count, parts=2)


def evaluated(dyn: Dynamics) -> "Evaluated":
    """The compiled program of ``dyn``, compiled once per Dynamics object."""
    found = _COMPILED.get(id(dyn))
    if found is None or found.dyn is not dyn:
        found = _COMPILED[id(dyn)] = Evaluated(dyn)
    return found


class Evaluated:
    """Numeric M(q), C(q, q̇), g(q) of a Dynamics through its compiled straight-line program;
    the model's parameters are inputs, given their default values."""

    def __init__(self, dyn: Dynamics):
        self.dyn = dyn
        params = [p.symbol for p in dyn.model.parameters]
        values = dyn.model.parameter_values
        self.values = [values[s] for s in params]
        self.f = compile_program(dyn.program, list(dyn.q) + list(dyn.qd) + params)

    def __call__(self, q, qd=None) -> dict:
        qd = np.zeros(len(q)) if qd is None else qd
        out = self.f(*q, *qd, *self.values)
        if "g" in out:
            out["g"] = out["g"][:, 0]
        return out


class PinocchioReference:
    """M (CRBA, symmetrised), C and g from Pinocchio, in our joint order (matched by name).

    A continuous joint read from URDF has two coordinates in Pinocchio (cos q, sin q) and one
    velocity; everything else has one of each."""

    def __init__(self, model: RobotModel, pmodel):
        import pinocchio as pin

        self.pin = pin
        self.pmodel = pmodel
        self.data = pmodel.createData()
        ours = {name: k for k, name in enumerate(model.joint_names)}
        assert sorted(pmodel.names[1:]) == sorted(ours) and pmodel.nv == model.dof
        self.joints = [(ours[pmodel.names[jid]], pmodel.joints[jid])
                       for jid in range(1, pmodel.njoints)]
        self.perm = np.empty(pmodel.nv, dtype=int)  # v_pin = v[perm]
        for k, joint in self.joints:
            assert joint.nv == 1 and joint.nq in (1, 2)
            self.perm[joint.idx_v] = k
        self.inv = np.argsort(self.perm)

    def configuration(self, q) -> np.ndarray:
        x = np.empty(self.pmodel.nq)
        for k, joint in self.joints:
            if joint.nq == 2:
                x[joint.idx_q:joint.idx_q + 2] = np.cos(q[k]), np.sin(q[k])
            else:
                x[joint.idx_q] = q[k]
        return x

    def __call__(self, q, qd) -> dict:
        pin, pm, data, inv = self.pin, self.pmodel, self.data, self.inv
        x, v = self.configuration(q), np.asarray(qd)[self.perm]
        M = np.array(pin.crba(pm, data, x))
        M = np.triu(M) + np.triu(M, 1).T  # CRBA fills the upper triangle
        C = np.array(pin.computeCoriolisMatrix(pm, data, x, v))
        g = np.array(pin.computeGeneralizedGravity(pm, data, x))
        return {"M": M[np.ix_(inv, inv)], "C": C[np.ix_(inv, inv)], "g": g[inv]}


def compare_with_pinocchio(dyn: Dynamics, ref: PinocchioReference, seed: int) -> None:
    evaluate = evaluated(dyn)
    rng = np.random.default_rng(seed)
    for q, qd in random_states(rng, dyn.model.dof):
        ours, theirs = evaluate(q, qd), ref(q, qd)
        for name in ("M", "C", "g"):
            assert_close(ours[name], theirs[name], what=f"{dyn.model.name} {name} at q={q}")


# ----------------------------------------------------------------------------------------------
# The planar two-link arm against the textbook
# ----------------------------------------------------------------------------------------------


@functools.cache
def planar() -> Dynamics:
    return derive(eomgen.load(example_path("planar_2link")))


def planar_textbook(dyn: Dynamics) -> dict:
    """Spong, Hutchinson & Vidyasagar, Robot Modeling and Control, the planar 2R arm (gravity
    along −y, angles from the x axis, joint 2 relative to link 1)."""
    q1, q2 = dyn.q
    qd1, qd2 = dyn.qd
    m1, m2, l1, lc1, lc2, I1, I2, g = (parameter_symbol(n) for n in
                                       ("m1", "m2", "l1", "lc1", "lc2", "I1", "I2", "g"))
    c2, s2 = sp.cos(q2), sp.sin(q2)
    M = sp.Matrix([
        [m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2,
         m2 * (lc2**2 + l1 * lc2 * c2) + I2],
        [m2 * (lc2**2 + l1 * lc2 * c2) + I2, m2 * lc2**2 + I2],
    ])
    h = -m2 * l1 * lc2 * s2
    C = sp.Matrix([[h * qd2, h * (qd1 + qd2)], [-h * qd1, 0]])
    gv = sp.Matrix([
        (m1 * lc1 + m2 * l1) * g * sp.cos(q1) + m2 * lc2 * g * sp.cos(q1 + q2),
        m2 * lc2 * g * sp.cos(q1 + q2),
    ])
    # energies from the link positions, independently of M: K = Σ ½ m |v_c|² + ½ I ω²
    t = sp.Symbol("t")
    a1, a2 = sp.Function("a1")(t), sp.Function("a2")(t)
    com1 = sp.Matrix([lc1 * sp.cos(a1), lc1 * sp.sin(a1)])
    com2 = sp.Matrix([l1 * sp.cos(a1) + lc2 * sp.cos(a1 + a2),
                      l1 * sp.sin(a1) + lc2 * sp.sin(a1 + a2)])
    v1, v2 = com1.diff(t), com2.diff(t)
    K = (m1 * v1.dot(v1) + m2 * v2.dot(v2) + I1 * a1.diff(t) ** 2
         + I2 * (a1.diff(t) + a2.diff(t)) ** 2) / 2
    K = K.subs({a1.diff(t): qd1, a2.diff(t): qd2}).subs({a1: q1, a2: q2})
    P = g * (m1 * com1[1] + m2 * com2[1]).subs({a1: q1, a2: q2})  # height along +y
    return {"M": M, "C": C, "g": gv, "K": K, "P": P}


def expand_all(x, q=()):
    """Expand products and trig sums (cos(q1 + q2) → cos q1 cos q2 − sin q1 sin q2); for the
    given q, also reduce modulo sin² q_i + cos² q_i − 1 (a remainder of degree < 2 in sin q_i,
    which is 0 exactly when x vanishes identically)."""
    x = sp.expand(sp.expand_trig(sp.expand(x)))
    for qi in q:
        s_, c_ = sp.Dummy("s"), sp.Dummy("c")
        x = sp.expand(x.xreplace({sp.sin(qi): s_, sp.cos(qi): c_}))
        if x.has(s_):
            x = sp.rem(x, s_**2 + c_**2 - 1, s_)
        x = sp.expand(x).xreplace({s_: sp.sin(qi), c_: sp.cos(qi)})
    return x


@pytest.mark.parametrize("name", ["M", "C", "g"])
def test_planar_2link_is_the_textbook(name):
    dyn = planar()
    ours, textbook = getattr(dyn, name), planar_textbook(dyn)[name]
    zeros = sp.zeros(*textbook.shape)
    assert sp.simplify(ours - textbook) == zeros
    assert (ours - textbook).applyfunc(expand_all) == zeros
    if name != "g":  # M and C come out in the textbook's own form: plain expansion suffices
        assert (ours - textbook).applyfunc(sp.expand) == zeros


def test_planar_2link_energies():
    dyn = planar()
    textbook = planar_textbook(dyn)
    qd = sp.Matrix(dyn.qd)
    assert sp.expand(dyn.K - (qd.T * dyn.M * qd)[0, 0] / 2) == 0
    assert expand_all(dyn.K - textbook["K"], dyn.q) == 0
    assert expand_all(dyn.P - textbook["P"], dyn.q) == 0
    gradient = sp.Matrix([dyn.P.diff(qi) for qi in dyn.q])
    assert (gradient - dyn.g).applyfunc(expand_all) == sp.zeros(2, 1)


def test_planar_2link_energies_match_numeric_model():
    """K and P evaluated at the default parameters agree with eomgen.numeric's."""
    dyn = planar()
    values = dyn.model.parameter_values
    nm = numeric_model(dyn.model)
    K = sp.lambdify([dyn.q, dyn.qd], dyn.K.xreplace(values))
    P = sp.lambdify([dyn.q], dyn.P.xreplace(values))
    rng = np.random.default_rng(1)
    for q, qd in random_states(rng, 2):
        assert_close(K(q, qd), kinetic_energy(nm, q, qd), rtol=1e-12)
        assert_close(P(q), potential_energy(nm, q), rtol=1e-12)


# ----------------------------------------------------------------------------------------------
# example-robot-data against Pinocchio's URDF reader
# ----------------------------------------------------------------------------------------------

ARMS = {
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "kinova": "kinova_description/robots/kinova.urdf",
    "xarm7": "xarm_description/urdf/xarm7.urdf",
    "so100": "so_arm_description/urdf/so100.urdf",
    "z1": "z1_description/urdf/z1.urdf",
    "double_pendulum": "double_pendulum_description/urdf/double_pendulum.urdf",
}
FINGERS = ("panda_finger_joint1", "panda_finger_joint2")


def erd_path(name: str) -> Path:
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    return robots / ARMS[name]


@functools.cache
def erd_model(name: str) -> RobotModel:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)  # Panda's finger <mimic>
        return eomgen.load(erd_path(name), couplings=False)  # as Pinocchio's default


@functools.cache
def erd_dynamics(name: str, locked: tuple = ()) -> Dynamics:
    model = erd_model(name)
    return derive(lock_joints(model, dict(locked)) if locked else model)


@pytest.mark.parametrize("name", sorted(ARMS))
def test_arm_matches_pinocchio(name):
    pin = need("pinocchio")
    dyn = erd_dynamics(name)
    pmodel = pin.buildModelFromUrdf(str(erd_path(name)))
    assert dyn.joint_names == tuple(pmodel.names[1:])  # chains: the same order
    compare_with_pinocchio(dyn, PinocchioReference(dyn.model, pmodel), seed=len(name))


@pytest.mark.parametrize("fingers", [(0.0, 0.0), (0.01, 0.035)], ids=["closed", "open"])
def test_panda_with_locked_fingers_matches_reduced_pinocchio(fingers):
    pin = need("pinocchio")
    dyn = erd_dynamics("panda", tuple(zip(FINGERS, fingers)))
    assert dyn.joint_names == tuple(f"panda_joint{k}" for k in range(1, 8))
    full = pin.buildModelFromUrdf(str(erd_path("panda")))
    q_ref = pin.neutral(full)
    ids = [full.getJointId(name) for name in FINGERS]
    for jid, value in zip(ids, fingers):
        q_ref[full.joints[jid].idx_q] = value
    reduced = pin.buildReducedModel(full, ids, q_ref)
    compare_with_pinocchio(dyn, PinocchioReference(dyn.model, reduced), seed=11)


def test_panda_fingers_free_are_independent_prismatic_joints():
    dyn = erd_dynamics("panda")
    assert dyn.joint_names[-2:] == FINGERS and dyn.model.dof == 9
    # the fingers are sibling branches of the hand: M does not couple them
    M = evaluated(dyn)(np.zeros(9))["M"]
    assert M[7, 8] == pytest.approx(0.0, abs=1e-15)


# ----------------------------------------------------------------------------------------------
# Random chains and trees against Pinocchio models built joint by joint
# ----------------------------------------------------------------------------------------------

#: (seed, joints, tree, prismatic, fixed links)
RANDOM = [
    (0, 1, False, True, True),
    (1, 2, True, True, True),
    (2, 3, False, False, True),
    (3, 4, True, True, False),
    (4, 5, False, True, True),
    (5, 6, True, True, True),
    (6, 8, True, True, True),
]


def random_id(case) -> str:
    seed, n, tree, prismatic, fixed = case
    return f"seed{seed}-{n}{'tree' if tree else 'chain'}" + ("" if prismatic else "-revolute")


@functools.cache
def random_model(case) -> RobotModel:
    seed, n, tree, prismatic, fixed = case
    return random_robot(np.random.default_rng(seed), n, tree=tree, prismatic=prismatic,
                        fixed_links=fixed)


@functools.cache
def random_dynamics(case) -> Dynamics:
    return derive(random_model(case))


def test_random_robots_cover_the_features():
    """The cases exercise what they claim: prismatic joints, fixed links, branches, and a joint
    order that differs from the tree order."""
    models = [random_model(c) for c in RANDOM]
    assert any(j.type.value == "prismatic" for m in models for j in m.joints)
    assert any(j.type.value == "fixed" for m in models for j in m.joints)
    assert any(m.joint_names != tuple(j.name for j in m.topological_joints if j.type.is_movable)
               for m in models)
    branched = [m for m in models if len({j.parent for j in m.joints}) < len(m.joints)]
    assert branched


@pytest.mark.parametrize("case", RANDOM, ids=random_id)
def test_random_robot_matches_pinocchio(case):
    need("pinocchio")
    dyn = random_dynamics(case)
    compare_with_pinocchio(dyn, PinocchioReference(dyn.model, to_pinocchio(dyn.model)),
                           seed=case[0] + 100)


# ----------------------------------------------------------------------------------------------
# C from the Christoffel symbols of the first kind
# ----------------------------------------------------------------------------------------------


def christoffel_C(evaluate: Evaluated, q, qd, h=1e-30) -> np.ndarray:
    """C_ij = Σ_k ½(∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) q̇_k, with ∂M/∂q_k by complex step
    (no subtraction, so exact to rounding)."""
    n = len(q)
    dM = np.array([evaluate(q + 1j * h * e, qd)["M"].imag / h for e in np.eye(n)])  # [k, i, j]
    C = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            C[i, j] = sum(0.5 * (dM[k, i, j] + dM[j, i, k] - dM[i, j, k]) * qd[k]
                          for k in range(n))
    return C


@pytest.mark.parametrize("which", ["planar", "ur5", "seed2-3chain-revolute", "seed4-5chain",
                                   "seed5-6tree"])
def test_C_is_built_from_christoffel_symbols(which):
    if which == "planar":
        dyn = planar()
    elif which == "ur5":
        dyn = erd_dynamics("ur5")
    else:
        dyn = random_dynamics(next(c for c in RANDOM if random_id(c) == which))
    evaluate = evaluated(dyn)
    rng = np.random.default_rng(3)
    for q, qd in random_states(rng, dyn.model.dof, 2):
        C = evaluate(q, qd)["C"]
        assert_close(C, christoffel_C(evaluate, q, qd), rtol=1e-10, what=f"{which} C")
        # and what the Christoffel form implies: Ṁ = C + Cᵀ
        Mdot = evaluate(q + 1j * 1e-30 * qd, qd)["M"].imag / 1e-30
        assert_close(C + C.T, Mdot, rtol=1e-10, what=f"{which} Mdot")


def test_christoffel_reference_agrees_with_central_differences():
    """The complex-step helper itself, against plain central differences."""
    dyn = random_dynamics(RANDOM[2])
    evaluate = evaluated(dyn)
    q, qd = random_states(np.random.default_rng(0), dyn.model.dof, 1)[0]
    h = 1e-6
    n = len(q)
    dM = np.array([(evaluate(q + h * e, qd)["M"] - evaluate(q - h * e, qd)["M"]) / (2 * h)
                   for e in np.eye(n)])
    C = np.einsum("kij,k->ij", dM, qd) + np.einsum("jik,k->ij", dM, qd) - \
        np.einsum("ijk,k->ij", dM, qd)
    assert_close(christoffel_C(evaluate, q, qd), C / 2, rtol=1e-7)


# ----------------------------------------------------------------------------------------------
# Outputs on demand
# ----------------------------------------------------------------------------------------------

#: Names of the intermediates that only the Coriolis matrix needs (see
#: symbolic.composite.coriolis_program): its entries, velocities V, Ṡ, subtree momenta and
#: inertia rates, and the forces F1, F3 of Echeandia and Wensing's recursion.
C_ONLY = re.compile(r"^(C\d+_\d+|Sd\d|V\d|hV\d|hd\d|Id\d|Fa\d|Fb\d)")
M_ENTRY, G_ENTRY = re.compile(r"^M\d+_\d+$"), re.compile(r"^(g\d+|P)$")


def test_gravity_only_computes_no_coriolis_or_mass_matrix():
    model = random_model(RANDOM[3])
    dyn = derive(model, outputs=["g"])
    assert dyn.outputs == ("g", "P")
    names = [s.name for s, _ in dyn.program.assignments]
    assert not [n for n in names if C_ONLY.match(n)], names
    assert not [n for n in names if M_ENTRY.match(n)], names  # no mass matrix entries either
    full = evaluated(random_dynamics(RANDOM[3]))
    only_g = Evaluated(dyn)
    for q, _ in random_states(np.random.default_rng(5), model.dof):
        assert_close(only_g(q)["g"], full(q)["g"], rtol=1e-14)
    with pytest.raises(KeyError, match="C was not derived"):
        dyn.C


def test_C_alone_matches_the_full_derivation():
    model = random_model(RANDOM[3])
    dyn = derive(model, outputs=("C",))
    assert "C" in dyn.outputs and "g" not in dyn.outputs and "P" not in dyn.outputs
    full = evaluated(random_dynamics(RANDOM[3]))
    only_c = Evaluated(dyn)
    for q, qd in random_states(np.random.default_rng(6), model.dof):
        assert_close(only_c(q, qd)["C"], full(q, qd)["C"], rtol=1e-14)


def test_C_alone_outputs_only_C():
    dyn = derive(random_model(RANDOM[1]), outputs=["C"])
    assert dyn.outputs == ("C",)
    names = [s.name for s, _ in dyn.program.assignments]
    assert not [n for n in names if M_ENTRY.match(n) or G_ENTRY.match(n)], names


def test_M_alone_has_no_coriolis_intermediates():
    dyn = derive(random_model(RANDOM[3]), outputs=["M"])
    assert dyn.outputs == ("M",)
    names = [s.name for s, _ in dyn.program.assignments]
    assert not [n for n in names if C_ONLY.match(n) or G_ENTRY.match(n)], names


@pytest.mark.parametrize("outputs", [["M", "Cqd"], ["c"], ["Mdot"]])
def test_unknown_output_is_a_value_error(outputs):
    with pytest.raises(ValueError, match="unknown outputs"):
        derive(planar().model, outputs=outputs)


# ----------------------------------------------------------------------------------------------
# Symbolic parameters
# ----------------------------------------------------------------------------------------------

DH_SYMBOLIC = """\
name: two_link_dh
convention: standard
gravity: [0, 0, -g]
parameters: {a1: 0.8, a2: 0.6, d2: 0.1, m1: 2.0, m2: 1.5, lc: 0.25, g: 9.81, J: 0.02}
dh:
  - {a: a1, alpha: pi/2, mass: m1, com: [-a1/2, 0, 0], inertia: {ixx: J, iyy: m1*a1**2/12, izz: m1*a1**2/12}}
  - {a: a2, d: d2, alpha: 0, mass: m2, com: [-lc, 0, 0], inertia: {ixx: J/2, iyy: 0.01, izz: 0.01}}
"""


@pytest.mark.parametrize("which", ["dh", "planar_2link"])
def test_parameters_stay_symbolic_and_substitute_to_the_numeric_model(tmp_path, which):
    if which == "dh":
        path = tmp_path / "two_link_dh.yaml"
        path.write_text(DH_SYMBOLIC, encoding="utf-8")
        model = eomgen.load(path)
        dyn = derive(model, simplify=False)  # trigsimp with symbols is slow and not the point
    else:
        dyn = planar()
        model = dyn.model
    used = {"dh": {"a1", "a2", "d2", "m1", "m2", "lc", "J"},
            "planar_2link": {"m1", "m2", "l1", "lc1", "lc2", "I1", "I2"}}[which]
    assert used <= {s.name for s in dyn.M.free_symbols}
    assert "g" in {s.name for s in dyn.g.free_symbols}
    assert not ({s.name for s in dyn.M.free_symbols} - used - {"q1", "q2"})
    values = model.parameter_values
    numeric = derive(model.with_numeric_parameters(), simplify=False)
    assert not numeric.M.free_symbols - set(numeric.q)
    rng = np.random.default_rng(8)
    for name in ("M", "C", "g"):
        substituted = sp.lambdify([dyn.q, dyn.qd], getattr(dyn, name).xreplace(values))
        direct = sp.lambdify([numeric.q, numeric.qd], getattr(numeric, name))
        for q, qd in random_states(rng, 2):
            assert_close(substituted(q, qd), direct(q, qd), rtol=1e-12, what=name)
    # and through the programs, the parameters given as inputs
    ev, ev_num = Evaluated(dyn), Evaluated(numeric)
    for q, qd in random_states(rng, 2):
        a, b = ev(q, qd), ev_num(q, qd)
        for name in ("M", "C", "g"):
            assert_close(a[name], b[name], rtol=1e-12, what=name)


def test_parameter_values_can_be_changed_after_deriving():
    """Deriving once and substituting other values equals deriving with those values."""
    model = eomgen.load(example_path("planar_2link"))
    dyn = planar()
    other = {parameter_symbol("m2"): 3.0, parameter_symbol("l1"): 0.4,
             parameter_symbol("I2"): 0.2}
    direct = derive(model.with_numeric_parameters(other), simplify=False)
    values = {**model.parameter_values, **other}
    rng = np.random.default_rng(9)
    for name in ("M", "C", "g"):
        substituted = sp.lambdify([dyn.q, dyn.qd], getattr(dyn, name).xreplace(values))
        derived = sp.lambdify([direct.q, direct.qd], getattr(direct, name))
        for q, qd in random_states(rng, 2):
            assert_close(substituted(q, qd), derived(q, qd), rtol=1e-12, what=name)


# ----------------------------------------------------------------------------------------------
# Joint order = description order
# ----------------------------------------------------------------------------------------------

def branched_yaml(joint_order: list[str]) -> str:
    """A small tree (link1 → link2 on one branch, link3 on another, one prismatic joint) with
    the joints listed in the given order."""
    joints = {
        "shoulder": "{name: shoulder, type: revolute, parent: base, child: link1, axis: [0, 0, 1]}",
        "elbow": ("{name: elbow, type: revolute, parent: link1, child: link2, "
                  "origin: {xyz: [1, 0, 0], rpy: [pi/2, 0, 0]}, axis: [0, 0, 1]}"),
        "slider": ("{name: slider, type: prismatic, parent: base, child: link3, "
                   "origin: {xyz: [0, 1/2, 0]}, axis: [1, 0, 0]}"),
    }
    return "\n".join([
        "name: branched",
        "gravity: [0, 0, -10]",
        "links:",
        "  - {name: base}",
        "  - {name: link1, mass: 2, com: [1/2, 0, 0], inertia: {ixx: 1/10, iyy: 1/5, izz: 1/5}}",
        "  - {name: link2, mass: 1, com: [1/4, 0, 1/10], inertia: {ixx: 1/20, iyy: 1/10, izz: 1/10}}",
        "  - {name: link3, mass: 3, com: [0, 0, 1/5], inertia: {ixx: 1/5, iyy: 1/5, izz: 1/5}}",
        "joints:",
        *[f"  - {joints[name]}" for name in joint_order],
        "",
    ])


def test_joint_order_is_description_order_not_tree_order(tmp_path):
    tree_order = ["shoulder", "elbow", "slider"]
    listed = ["elbow", "slider", "shoulder"]  # the child's joint before its parent's
    dyns = {}
    for label, order in (("tree", tree_order), ("listed", listed)):
        path = tmp_path / f"{label}.yaml"
        path.write_text(branched_yaml(order), encoding="utf-8")
        dyns[label] = derive(eomgen.load(path), simplify=False)
    tree, shuffled = dyns["tree"], dyns["listed"]
    assert shuffled.joint_names == tuple(listed)
    assert tree.joint_names == tuple(tree_order)
    # q_k of the shuffled model is the joint listed k-th: rename and permute, then compare
    index = [tree_order.index(name) for name in listed]  # shuffled k ↔ tree index[k]
    rename = {}
    for k, t in enumerate(index):
        rename[tree.q[t]] = shuffled.q[k]
        rename[tree.qd[t]] = shuffled.qd[k]
    for name in ("M", "C", "g"):
        ours = getattr(shuffled, name)
        theirs = getattr(tree, name).xreplace(rename)
        if name == "g":
            expected = sp.Matrix([theirs[t, 0] for t in index])
        else:
            expected = sp.Matrix(3, 3, lambda i, j: theirs[index[i], index[j]])
        difference = (ours - expected).applyfunc(lambda e: expand_all(e, shuffled.q))
        assert difference == sp.zeros(*ours.shape), name
    # the slider (listed second) is q2: the (2, 2) entry is the mass it carries
    assert shuffled.M[1, 1] == 3
    assert shuffled.g[1, 0] == 0  # it slides horizontally


def test_derivation_steps_group_intermediates_by_their_tags_not_their_names():
    from eomgen.dynamics import STEP_FAMILIES

    from support.reference import random_robot

    # general axes: derive takes the world-frame composite programs, whose steps are tagged
    model = random_robot(np.random.default_rng(3), 3, prismatic=False, fixed_links=False)
    dyn = derive(model, outputs=("M", "C", "g"), simplify=False)
    tags = dyn.program.tags()
    by_step = {s.key: [name for name, _ in s.results] for s in dyn.steps}
    for step, families in STEP_FAMILIES.items():
        expected = [s.name for s, _ in dyn.program.assignments
                    if s in tags and tags[s].family in families]
        assert by_step[step] == expected, step
    assert by_step["kinematics"] and by_step["inertia"]
    # "Rh" (a rotated first moment) starts with "R" but is an inertia quantity: a grouping by
    # name prefix put it among the rotations
    rotated = [n for n in by_step["inertia"] if tags[sp.Symbol(n, real=True)].family == "Rh"]
    assert rotated and not set(rotated) & set(by_step["kinematics"])
