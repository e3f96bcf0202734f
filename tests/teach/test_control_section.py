"""The handout's adaptive-control section (eomgen/teach/control.py, issue 28) against
independent computations: the printed Slotine–Li regressor times the printed β equals
M q̈_r + C q̇_r + g from Pinocchio (CRBA, Christoffel symbols by central differences of its M,
RNEA for g); the printed Ṁ − 2C equals Pinocchio's Ṁ (differences) minus twice that C and is
skew; the section is in the handout of a plain teaching arm and not in one with drives."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.present import notation as nt
from eomgen.teach.content import HANDOUT_CONFIG, named_coriolis
from eomgen.teach.control import slotine_li_equations
from support.extras import need

pin = need("pinocchio")

TITLE = "Adaptive control: the Slotine–Li regressor"


def section_equations(name):
    model = eomgen.load(eomgen.example_path(name))
    dyn = eomgen.derive(model, outputs=("M", "C", "g"), simplify=False)
    book = nt.textbook_for(dyn, HANDOUT_CONFIG)
    coriolis = named_coriolis(dyn, book)
    return model, dyn, coriolis, slotine_li_equations(dyn, book, coriolis)


@pytest.fixture(scope="module")
def arm():
    return section_equations("planar_2link")


def pinocchio_terms(model):
    """M(q), the Christoffel C(q, q̇) (central differences of M, step 1e-6) and g(q)."""
    from eomgen.numeric.pinocchio import to_pinocchio

    p = to_pinocchio(model)
    n = model.dof

    def M(q):
        return p.crba(q)

    def C(q, qd, h=1e-6):
        dM = [(M(q + h * e) - M(q - h * e)) / (2 * h) for e in np.eye(n)]  # dM[k] = ∂M/∂q_k
        G = np.array([[[0.5 * (dM[k][i, j] + dM[j][i, k] - dM[i][j, k]) for k in range(n)]
                       for j in range(n)] for i in range(n)])
        return G @ qd

    def M_dot(q, qd, h=1e-6):
        return (M(q + h * qd) - M(q - h * qd)) / (2 * h)

    def g(q):
        return p.rnea(q, np.zeros(n), np.zeros(n))

    return M, C, M_dot, g


def check_regressor(model, dyn, eqs):
    values = model.parameter_values
    beta = np.array([float(b.subs(values)) for b in eqs.beta])
    Y = sp.lambdify([dyn.q, dyn.qd, eqs.qd_r, eqs.qdd_r], eqs.Y.subs(values), "numpy")
    M, C, _, g = pinocchio_terms(model)
    for q, qd, qd_r, qdd_r in np.random.default_rng(5).uniform(-2, 2, (5, 4, model.dof)):
        expected = M(q) @ qdd_r + C(q, qd) @ qd_r + g(q)
        np.testing.assert_allclose(np.array(Y(q, qd, qd_r, qdd_r), float) @ beta, expected,
                                   rtol=0, atol=1e-8)


def check_skew(model, dyn, coriolis, eqs):
    values = {nf.symbol: nf.value for nf in coriolis[0]}
    n = model.dof
    N = eqs.N.subs(values).subs(model.parameter_values)
    assert (N + N.T).applyfunc(lambda e: sp.simplify(sp.expand_trig(e))) == sp.zeros(n, n)
    _, C, M_dot, _ = pinocchio_terms(model)
    f = sp.lambdify([dyn.q, dyn.qd], N, "numpy")
    f_dot = sp.lambdify([dyn.q, dyn.qd], eqs.M_dot.subs(values).subs(model.parameter_values))
    for q, qd in np.random.default_rng(6).uniform(-2, 2, (4, 2, n)):
        np.testing.assert_allclose(np.array(f_dot(q, qd), float), M_dot(q, qd), atol=1e-8)
        np.testing.assert_allclose(np.array(f(q, qd), float), M_dot(q, qd) - 2 * C(q, qd),
                                   atol=1e-8)


def test_printed_regressor_times_beta_is_M_qdd_r_plus_C_qd_r_plus_g(arm):
    model, dyn, _, eqs = arm
    check_regressor(model, dyn, eqs)
    # the textbook's entry: row 2, column MX2 is g c12 + l1 (qdd_r1 c2 + qd1 qd_r1 s2)
    q1, q2 = dyn.q
    l1, g_ = (next(p.symbol for p in model.parameters if p.name == n) for n in ("l1", "g"))
    k = eqs.names.index("MX2")
    assert sp.expand(eqs.Y[1, k] - (g_ * sp.cos(q1 + q2) + l1 * eqs.qdd_r[0] * sp.cos(q2)
                                    + l1 * dyn.qd[0] * eqs.qd_r[0] * sp.sin(q2))) == 0


def test_printed_Mdot_minus_2C_is_skew_and_is_pinocchios(arm):
    model, dyn, coriolis, eqs = arm
    check_skew(model, dyn, coriolis, eqs)
    h = coriolis[0][0].symbol  # the printed form is the textbook's
    qd1, qd2 = dyn.qd
    assert sp.expand(eqs.N[0, 1] - h * (2 * qd1 + qd2)) == 0 and eqs.N[0, 0] == 0


def test_handout_has_the_section_for_a_plain_arm_only():
    from eomgen.teach import handout_files

    arm = eomgen.load(eomgen.example_path("planar_2link"))
    text = handout_files(arm, ["md"], check=False)[0].content
    section = text[text.index("## " + TITLE):]
    for needle in (r"\dot{q}_{r} &= \dot{q}_{d} - \Lambda \tilde{q}", r"Y_{2,4} &=",
                   r"\dot{\hat{\beta}} &= -\Gamma\, Y^{T} s",
                   r"-s^{T} K_{D}\, s + \tfrac{1}{2} s^{T} (\dot{M} - 2C)\, s",
                   r"\dot{M} - 2C &= \begin{pmatrix} 0 & h \left(2 \dot{q}_{1} + \dot{q}_{2}"
                   r"\right)", r"\mathrm{MX}_{1}^{R} &= l_{1} m_{2} + l_{c1} m_{1}"):
        assert needle in section, needle
    examples = Path(__file__).parents[2] / "examples" / "robots"
    flexible = eomgen.load(examples / "flexible_2link.yaml")
    assert TITLE not in handout_files(flexible, ["md"], check=False)[0].content


@pytest.mark.slow
def test_elbow_arm_section_against_pinocchio():
    """The 3-joint elbow arm: three named factors; Ṁ − 2C printed as
    [[0, 2 h₁ q̇₁, −2 h₂ q̇₁], …, [2 h₂ q̇₁, −h₃ (2 q̇₂ + q̇₃), 0]] (zero diagonal)."""
    model, dyn, coriolis, eqs = section_equations("elbow_rrr")
    check_regressor(model, dyn, eqs)
    check_skew(model, dyn, coriolis, eqs)
    assert all(eqs.N[i, i] == 0 for i in range(3))
    assert not any(e.has(sp.sin, sp.cos) for e in eqs.N)  # every entry in the named factors
