"""The regressor τ = Y(q, q̇, q̈) π (eomgen.regressor) against independent computations:
eomgen.numeric's Newton–Euler and energies, Pinocchio's computeJointTorqueRegressor, and the
hand-derived base parameters of the planar two-link arm."""

from __future__ import annotations

import functools
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import eomgen
from support import erd_robots_dir, random_states
from eomgen.errors import UnsupportedError, UnsupportedFeatureWarning
from eomgen.numeric import kinetic_energy, numeric_model, potential_energy, rnea
from eomgen.regressor import (base_parameters, derive_regressor, identify, regressor_form,
                              symbolic_base_parameters)
from eomgen.symbolic.trigonometry import fourier_form
from support.reference import pin_q_order, planar_2link_by_hand, random_robot, to_pinocchio
from support.extras import need

URDF = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
}
SCENES = {"panda_arm": ("panda", "examples/scenes/panda_fingers_locked.yaml")}


def load(name: str):
    if name in ("planar_2link", "puma560_dh"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # PUMA link 1 is not a physical body (see its file)
            return eomgen.load(eomgen.example_path(name))
    if name in SCENES:
        robot, scene = SCENES[name]
        return eomgen.apply_scene(load(robot), eomgen.load_scene(scene))[0]
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)  # Panda's finger <mimic>
        return eomgen.load(robots / URDF[name], couplings=False)  # as Pinocchio's default


@functools.cache
def regressor(name: str, actuators: tuple = ()):
    if name.startswith("random"):
        seed, n, tree = {"random_chain": (8, 4, False), "random_tree": (1, 5, True)}[name]
        model = random_robot(np.random.default_rng(seed), n, tree=tree)
    else:
        model = load(name)
    return derive_regressor(model, actuators)


def states(n: int, count: int = 3, seed: int = 7):
    return random_states(seed, n, count)


@pytest.mark.parametrize("name", ["planar_2link", "puma560_dh", "ur5", "random_chain",
                                  "random_tree"])
def test_Y_pi_is_newton_euler_and_energies_are_linear(name):
    reg = regressor(name)
    nm = numeric_model(reg.model)
    f, pi = reg.compiled(), reg.numeric_parameters()
    # P up to a constant: links fixed to the root have no column but count in numeric's P
    zero = np.zeros(reg.n)
    P0 = potential_energy(nm, zero) - f(zero, zero, zero)["P"] @ pi
    for q, qd, qdd in states(reg.n):
        out = f(q, qd, qdd)
        tau = rnea(nm, q, qd, qdd)
        np.testing.assert_allclose(out["Y"] @ pi, tau, rtol=1e-10, atol=1e-10 * np.abs(tau).max())
        assert out["K"] @ pi == pytest.approx([kinetic_energy(nm, q, qd)], rel=1e-10, abs=1e-12)
        assert out["P"] @ pi + P0 == pytest.approx([potential_energy(nm, q)], rel=1e-10,
                                                   abs=1e-10)


def test_random_models_have_prismatic_joints_and_merged_links():
    for name in ("random_chain", "random_tree"):
        tree = regressor(name).tree
        assert any(not b.joint.type.is_revolute for b in tree.bodies)
        assert any(len(b.links) > 1 for b in tree.bodies)


def test_actuator_columns_add_armature_friction_and_offset():
    reg = regressor("puma560_dh", ("armature", "viscous", "coulomb", "offset"))
    n = reg.n
    assert reg.PARAMETER_NAMES[10 * n:10 * n + 2] == ("IA1", "IA2")
    assert reg.PARAMETER_NAMES[-1] == "FO6"
    rng = np.random.default_rng(3)
    extra = {f"{kind}{k + 1}": float(rng.uniform(0.1, 2)) for kind in ("IA", "FV", "FC", "FO")
             for k in range(n)}
    pi = np.array([float(x) for x in reg.inertial_parameters(reg.model.parameter_values, extra)])
    nm = numeric_model(reg.model)
    coef = {kind: np.array([extra[f"{kind}{k + 1}"] for k in range(n)]) for kind in
            ("IA", "FV", "FC", "FO")}
    f = reg.compiled()
    for q, qd, qdd in states(n):
        expected = (rnea(nm, q, qd, qdd) + coef["IA"] * qdd + coef["FV"] * qd
                    + coef["FC"] * np.sign(qd) + coef["FO"])
        np.testing.assert_allclose(f(q, qd, qdd)["Y"] @ pi, expected, rtol=1e-10)


def test_unknown_actuator_term_is_refused():
    with pytest.raises(ValueError, match="actuator terms"):
        derive_regressor(load("planar_2link"), ("stiction",))


# ----------------------------------------------------------------------------------------------
# Pinocchio, column by column
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["ur5", "panda", "random_tree"])
def test_Y_equals_pinocchio_column_by_column(name):
    pin = need("pinocchio")
    reg = regressor(name)
    if name in URDF:
        pmodel = pin.buildModelFromUrdf(str(erd_robots_dir() / URDF[name]))
    else:
        pmodel = to_pinocchio(reg.model)
    perm = pin_q_order(reg.model, pmodel)  # pinocchio coordinate k is our joint perm[k]
    cols = np.concatenate([np.arange(10) + 10 * perm[k] for k in range(reg.n)])
    pi_pin = np.concatenate([pmodel.inertias[i].toDynamicParameters()
                             for i in range(1, pmodel.njoints)])
    np.testing.assert_allclose(reg.numeric_parameters()[cols], pi_pin, rtol=1e-12, atol=1e-14)
    data = pmodel.createData()
    f = reg.compiled()
    for q, qd, qdd in states(reg.n, 2):
        Y = f(q, qd, qdd)["Y"][np.ix_(perm, cols)]
        Y_pin = pin.computeJointTorqueRegressor(pmodel, data, q[perm], qd[perm], qdd[perm])
        # UR5: our parser snaps rpy-derived rotation entries within 1e-11 of 0/±1, Pinocchio not
        np.testing.assert_allclose(Y, Y_pin, rtol=0, atol=1e-9 * np.abs(Y_pin).max())


# ----------------------------------------------------------------------------------------------
# Base parameters
# ----------------------------------------------------------------------------------------------

#: Published counts: PUMA 560 (Khalil & Dombre, "Modeling, Identification and Control of
#: Robots", 2002, §12.5 and Table 12.x: 36 inertial, + 12 with viscous and Coulomb friction),
#: UR5 36, Panda 43 (Gaz, Cognetti, Oliva, Robuffo Giordano, De Luca, "Dynamic identification
#: of the Franka Emika Panda robot with retrieval of feasible parameters using
#: penalty-based optimization", IEEE RA-L 2019: 43, + 14 friction = 57).
COUNTS = [("puma560_dh", (), 36), ("puma560_dh", ("viscous", "coulomb"), 48),
          ("ur5", (), 36), ("panda_arm", (), 43), ("panda_arm", ("viscous", "coulomb"), 57)]


@pytest.mark.parametrize("name, actuators, count", COUNTS)
def test_base_parameter_counts_are_the_published_ones(name, actuators, count):
    reg = regressor(name, actuators)
    base = base_parameters(reg)
    assert base.count == base.rank == count
    assert base.gap[0] > 1e4 * base.gap[1]  # a clear gap between kept and dropped
    # Y_base β = Y π and Y_base has full column rank, at states the sampling never saw
    f, pi = reg.compiled(), reg.numeric_parameters()
    rng = np.random.default_rng(99)
    pi = pi + rng.uniform(0.5, 1.5, pi.size) * (pi == 0)  # every parameter in play
    stack = []
    for q, qd, qdd in states(reg.n, count // reg.n + 3, seed=123):  # enough rows for rank
        Y = f(q, qd, qdd)["Y"]
        stack.append(Y[:, list(base.base)])
        np.testing.assert_allclose(stack[-1] @ base.beta(pi), Y @ pi, rtol=1e-9,
                                   atol=1e-9 * np.abs(Y @ pi).max())
    assert np.linalg.matrix_rank(np.vstack(stack)) == count


def test_planar_2link_base_parameters_are_the_closed_form():
    """By hand (the grouping rules of Khalil & Dombre §12.5.2, or directly from M and g of the
    planar arm): with l1 the length of link 1, joint axes along z and gravity in the plane,

        M11 = ZZ1 + ZZ2 + l1² M2 + 2 l1 (MX2 cos q2 − MY2 sin q2),  M22 = ZZ2, …
        g1  = γ ((MX1 + l1 M2) cos q1 − MY1 sin q1) + …

    so the base parameters are MX1 + l1 M2, MY1, ZZ1 + l1² M2, MX2, MY2, ZZ2: six. Every other
    column is zero (M1 and MZ's and the tilted inertias do not act in the plane).
    """
    reg = regressor("planar_2link")
    l1 = 0.7
    base = base_parameters(reg, values={"l1": l1})
    names = [reg.PARAMETER_NAMES[k] for k in base.base]
    assert names == ["MX1", "MY1", "ZZ1", "MX2", "MY2", "ZZ2"]
    m2 = reg.PARAMETER_NAMES.index("M2")
    expected = np.zeros((6, len(base.dependent)))
    expected[0, base.dependent.index(m2)] = l1
    expected[2, base.dependent.index(m2)] = l1 ** 2
    np.testing.assert_allclose(base.K, expected, atol=1e-12)
    assert [name for name, _ in base.expressions()] == ["MX1R", "MY1", "ZZ1R", "MX2", "MY2",
                                                        "ZZ2"]


# ----------------------------------------------------------------------------------------------
# Symbolic base parameters (closed-form grouping) against the numeric route
# ----------------------------------------------------------------------------------------------

PUMA_SYMBOLIC = {"a: 0.4318": "a: a2", "a: 0.0203": "a: a3", "d: 0.15005": "d: d3",
                 "d: 0.4318": "d: d4"}


@functools.cache
def puma_symbolic_geometry():
    """The PUMA 560 with its DH lengths a2, a3, d3, d4 kept as symbols."""
    text = eomgen.example_path("puma560_dh").read_text()
    for old, new in PUMA_SYMBOLIC.items():
        assert text.count(old) == 1
        text = text.replace(old, new)
    text = text.replace("\ndh:\n", "\nparameters: {a2: 0.4318, a3: 0.0203, d3: 0.15005, "
                        "d4: 0.4318}\ndh:\n", 1)
    path = Path(tempfile.mkdtemp()) / "puma560_symbolic.yaml"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return derive_regressor(eomgen.load(path))


def test_planar_2link_symbolic_grouping_is_the_closed_form():
    reg = regressor("planar_2link")
    base = symbolic_base_parameters(reg)
    M2, MX1, ZZ1 = (sp.Symbol(n, real=True) for n in ("M2", "MX1", "ZZ1"))
    l1 = sp.Symbol("l1", real=True)
    got = dict(zip(base.names, base.expressions))
    assert list(got) == ["MX1R", "MY1", "ZZ1R", "MX2", "MY2", "ZZ2"]
    assert sp.expand(got["MX1R"] - (MX1 + l1 * M2)) == 0
    assert sp.expand(got["ZZ1R"] - (ZZ1 + l1 ** 2 * M2)) == 0
    assert base.residual == ()


@pytest.mark.parametrize("name", ["puma560_dh", "ur5", "panda_arm"])
def test_symbolic_and_numeric_base_parameters_agree(name):
    reg = regressor(name)
    symbolic, numeric = symbolic_base_parameters(reg), base_parameters(reg)
    assert symbolic.residual == ()  # the rules alone leave no dependency on these arms
    assert symbolic.base == numeric.base
    pi = np.random.default_rng(4).uniform(-1, 1, reg.p)
    np.testing.assert_allclose(symbolic.beta(pi), numeric.beta(pi), rtol=1e-9, atol=1e-12)


def test_symbolic_geometry_puma_base_parameters():
    """DH lengths stay symbols in β; at other lengths β matches the numeric route there."""
    reg = puma_symbolic_geometry()
    base = symbolic_base_parameters(reg)
    assert base.count == 36
    got = dict(zip(base.names, base.expressions))
    a2 = sp.Symbol("a2", real=True)
    M, MX2, XX2, YY2 = ([sp.Symbol(f"M{k}", real=True) for k in (3, 4, 5, 6)],
                        *(sp.Symbol(n, real=True) for n in ("MX2", "XX2", "YY2")))
    assert sp.expand(got["MX2R"] - (MX2 + a2 * sum(M))) == 0
    assert sp.expand(got["XX2R"] - (XX2 - YY2 - a2 ** 2 * sum(M))) == 0
    other = {"a2": 0.6, "a3": 0.05, "d3": 0.2, "d4": 0.3}
    numeric = base_parameters(reg, values=other)
    assert numeric.base == base.base
    pi = np.random.default_rng(5).uniform(-1, 1, reg.p)
    np.testing.assert_allclose(base.beta(pi, other), numeric.beta(pi), rtol=1e-9, atol=1e-12)
    assert base.latex().startswith("\\begin{aligned}\n\\mathrm{ZZ}_{1}^{R} &= ")


def test_base_program_computes_the_base_columns():
    reg = regressor("puma560_dh")
    base = base_parameters(reg)
    full, only = reg.compiled(), reg.compiled(program=reg.base_program(base.base))
    for q, qd, qdd in states(reg.n, 2):
        np.testing.assert_array_equal(only(q, qd, qdd)["Y_base"],
                                      full(q, qd, qdd)["Y"][:, list(base.base)])
    assert reg.operation_count(base.base) < reg.operation_count()


def test_symbolic_route_reports_what_its_rules_leave_on_prismatic_chains():
    reg = regressor("random_chain")  # two prismatic joints between two revolute ones
    symbolic, numeric = symbolic_base_parameters(reg), base_parameters(reg)
    assert symbolic.count == numeric.count
    assert symbolic.residual  # the prismatic special cases are found numerically
    f, pi = reg.compiled(), np.random.default_rng(6).uniform(-1, 1, reg.p)
    for q, qd, qdd in states(reg.n, 2):
        Y = f(q, qd, qdd)["Y"]
        np.testing.assert_allclose(Y[:, list(symbolic.base)] @ symbolic.beta(pi), Y @ pi,
                                   rtol=1e-9, atol=1e-9)


def test_symbolic_route_refuses_a_tilted_revolute_axis():
    with pytest.raises(UnsupportedError, match=r"^<random>: symbolic base parameters: joint "
                       r"'joint\d+': the closed-form grouping needs a revolute axis along"):
        symbolic_base_parameters(regressor("random_tree"))


def test_a_model_without_movable_joints_has_no_parameters():
    from eomgen.model import Inertial, Link, build_model

    reg = derive_regressor(build_model("<test>", "block", [Link("base", Inertial(1.0))], []))
    assert reg.p == 0 and base_parameters(reg).count == 0
    assert symbolic_base_parameters(reg).count == 0


def test_planar_2link_Y_pi_is_the_lagrangian_tau_exactly():
    """Symbolic identity on the expanded expressions: Y π = M q̈ + C q̇ + g (eomgen.derive)."""
    reg = regressor("planar_2link")
    dyn = eomgen.derive(reg.model)
    difference = reg.Y * reg.inertial_parameters() - dyn.tau
    assert all(sp.simplify(sp.expand(e)) == 0 for e in difference)


def test_written_out_planar_regressor_is_the_hand_derivation():
    """regressor_form (what the LaTeX document and the notebook print): the non-zero columns
    named and equal to the closed form by hand, the 13 others zero; β the hand grouping
    MX1 + l1 M2, ZZ1 + l1² M2; Y_base β = Y π exactly in SymPy; and the hand form with the
    description's π is M q̈ + C q̇ + g of eomgen.derive (a third computation)."""
    model = load("planar_2link")
    form = regressor_form(model)
    hand, q, l1 = planar_2link_by_hand()
    assert form.names == tuple(hand)
    assert len(form.zero) == 13 and form.Y.shape == (2, 7)
    for c, name in enumerate(form.names):
        for i in range(2):
            assert fourier_form(form.Y[i, c] - hand[name][i], q) == 0, (name, i)
    P = {name: sp.Symbol(name, real=True) for name in form.regressor.PARAMETER_NAMES}
    assert dict(zip(form.base_names, form.beta)) == {
        "MX1R": P["MX1"] + l1 * P["M2"], "MY1": P["MY1"], "ZZ1R": P["ZZ1"] + l1 ** 2 * P["M2"],
        "MX2": P["MX2"], "MY2": P["MY2"], "ZZ2": P["ZZ2"]}
    assert form.exact
    identity = form.Y_base * sp.Matrix(form.beta) - form.Y * form.pi
    assert all(fourier_form(e, q) == 0 for e in identity)
    dyn = eomgen.derive(model)
    pi = form.regressor.inertial_parameters()
    tau = dyn.M * sp.Matrix(dyn.qdd) + dyn.C * sp.Matrix(dyn.qd) + dyn.g
    by_hand = [sum(hand[name][i] * pi[form.regressor.PARAMETER_NAMES.index(name)]
                   for name in hand) for i in range(2)]
    assert all(fourier_form(by_hand[i] - tau[i], q) == 0 for i in range(2))


@pytest.mark.parametrize("name", ["elbow_rrr", "scara_rrp", "stanford_rrp"])
def test_written_out_base_regressor_reproduces_Y_pi(name):
    """Three-joint teaching arms (a residual dependency on the SCARA): Y_base β = Y π at
    random states and parameters, and the zero columns are zero in the numeric Y."""
    form = regressor_form(eomgen.load(eomgen.example_path(name)))
    reg = form.regressor
    rng = np.random.default_rng(2)
    values = {**reg.model.parameter_values,
              **dict(zip(reg.parameter_symbols, rng.uniform(0.5, 1.5, reg.p)))}
    Y = reg.compiled()
    for q, qd, qdd in states(reg.n, 2):
        at = {**values, **dict(zip(reg.q + reg.qd + reg.qdd, [*q, *qd, *qdd]))}
        lhs = np.array((form.Y_base * sp.Matrix(form.beta)).xreplace(at), dtype=float)
        rhs = np.array((form.Y * form.pi).xreplace(at), dtype=float)
        np.testing.assert_allclose(lhs, rhs, rtol=1e-10, atol=1e-10)
        full = Y(q, qd, qdd)["Y"]
        np.testing.assert_allclose(np.array(form.Y.xreplace(at), dtype=float),
                                   full[:, list(form.columns)], rtol=1e-10, atol=1e-10)
        assert np.all(np.abs(full[:, list(form.zero)]) < 1e-12)


def test_identification_recovers_beta_from_newton_euler_torques():
    """τ simulated by eomgen.numeric's RNEA (plus friction) for a π unlike the description's;
    least squares on the base regressor returns β(π) of that π."""
    reg = regressor("puma560_dh", ("viscous", "coulomb"))
    base = base_parameters(reg)
    rng = np.random.default_rng(11)
    n = reg.n
    fv, fc = rng.uniform(0.5, 2, n), rng.uniform(0.1, 1, n)
    nm = numeric_model(reg.model)
    samples = list(states(n, 30, seed=12))
    tau = [rnea(nm, *s) + fv * s[1] + fc * np.sign(s[1]) for s in samples]
    q, qd, qdd = (np.array([s[k] for s in samples]) for k in range(3))
    result = identify(reg, base, q, qd, qdd, np.array(tau))
    pi = np.concatenate([reg.numeric_parameters()[:10 * n], fv, fc])
    np.testing.assert_allclose(result.beta, base.beta(pi), rtol=1e-7, atol=1e-9)
    assert result.rms < 1e-9 and np.isfinite(result.condition)


def test_evaluating_without_a_parameter_value_names_it():
    from eomgen.errors import ParameterError
    from eomgen.model import Parameter
    from dataclasses import replace

    reg = regressor("planar_2link")
    model = replace(reg.model, parameters=tuple(
        Parameter(p.symbol) if p.name == "l1" else p for p in reg.model.parameters))
    with pytest.raises(ParameterError, match="no numeric value for l1$"):
        derive_regressor(model).compiled()
