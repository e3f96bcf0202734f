"""One form in a handout (a teacher's report): every section writes sines and cosines as the
mass matrix does, as products of s_k, c_k (never sin 2q_2 in one section and s_2 c_2 in the
next); the Christoffel symbols are printed grouped by body mass, as M is, and equal those of
the program's M (differentiated here, SymPy's simplify); the base parameters that are zero for
every value of the description's parameters are left out (which ones: from the inertial
parameters of the description, through regressor_form's base, not the section's own β); the
notebook prints q̇_r as the handout does."""

from __future__ import annotations

import re

import pytest
import sympy as sp

import eomgen
from eomgen.present.display import expression_latex
from eomgen.present import notation as nt
from eomgen.regressor import regressor_form
from eomgen.teach import handout_files
from eomgen.teach.content import HANDOUT_CONFIG, named_coriolis
from eomgen.teach.control import slotine_li_equations

ARMS = ["planar_2link", "elbow_rrr"]

#: A double angle as the printer writes it: \sin{\left(2 q_{2} \right)}, \cos{\left(2 q_{2} +
#: q_{3} \right)}, \sin{\left(2 \left(q_{2} + q_{3}\right) \right)}.
DOUBLE = re.compile(r"\\(?:sin|cos)\{\\left\(2 ")
#: A product of a sine and a cosine in the compact notation: s_{2} c_{2}, s_{23} c_{23}.
PRODUCT = re.compile(r"s_\{(\d+)\}(?:\^\{2\})? c_\{(\d+)\}")


@pytest.fixture(scope="module", params=ARMS)
def arm(request):
    model = eomgen.load(eomgen.example_path(request.param))
    dyn = eomgen.derive(model, outputs=("M", "C", "g"), simplify=False)
    book = nt.textbook_for(dyn, HANDOUT_CONFIG)
    coriolis = named_coriolis(dyn, book)
    markdown = handout_files(model, ["md"], check=False)[0].content
    return model, dyn, book, coriolis, markdown


def sections(markdown: str) -> dict[str, str]:
    parts = re.split(r"^## ", markdown, flags=re.M)[1:]
    return {part.splitlines()[0]: part for part in parts}


def test_no_section_writes_a_double_angle_where_another_writes_products(arm):
    *_, markdown = arm
    found = sections(markdown)
    double = [title for title, text in found.items() if DOUBLE.search(text)]
    products = [title for title, text in found.items() if PRODUCT.search(text)]
    assert not (double and products), (double, products)
    assert not double  # the handout's form is M's: products
    assert not re.search(r"\\(?:sin|cos)\{", markdown)  # everything in the compact notation
    if arm[0].name == "elbow_rrr":  # products do appear: M₁₁'s s₂², h₁'s s₂ c₂, Y's columns
        assert "Adaptive control: the Slotine–Li regressor" in products


def test_printed_christoffel_symbols_are_those_of_the_program(arm):
    """Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) of the M of derive's program (expanded,
    not the textbook algebra), against each printed Γ (named factors replaced by their values):
    sympy.simplify of the difference is zero, and the handout lists exactly the non-zero ones."""
    model, dyn, book, coriolis, markdown = arm
    names, christoffel, _ = coriolis
    values = {nf.symbol: nf.value for nf in names}
    M = dyn.named("M").expand()
    q = dyn.q
    n = model.dof
    printed = {key: value for key, value in christoffel}
    step6 = sections(markdown)["Step 6: Christoffel symbols and the Coriolis matrix"]
    for i in range(n):
        for j in range(n):
            for k in range(j, n):
                gamma = (M[i, j].diff(q[k]) + M[i, k].diff(q[j]) - M[j, k].diff(q[i])) / 2
                if (i, j, k) not in printed:
                    assert sp.simplify(gamma) == 0, (i, j, k)
                    assert rf"\Gamma_{{{i + 1},{j + 1},{k + 1}}} " not in step6
                    continue
                shown = sp.sympify(printed[i, j, k]).subs(values).doit()
                assert sp.simplify(sp.expand_trig(shown - gamma)) == 0, (i, j, k)
                assert rf"\Gamma_{{{i + 1},{j + 1},{k + 1}}}" in step6


def test_unnamed_christoffel_symbols_are_grouped_by_mass_as_M_is():
    """The PUMA's first three joints: no few common factors, so each Γ is printed, grouped by
    body mass (m₃ (…) + …), as the entries of M are; C entry by entry with the same groups."""
    model = eomgen.load(eomgen.example_path("puma560_arm3"))
    markdown = handout_files(model, ["md"], check=False)[0].content
    step6 = sections(markdown)["Step 6: Christoffel symbols and the Coriolis matrix"]
    assert r"\Gamma_{1,2,2} &= m_{3} d_{3} \left(" in step6
    assert r"\Gamma_{3,2,2} &= m_{3} a_{2} \left(a_{3} s_{3} + l_{c3} c_{3}\right)" in step6
    assert r"C_{2,2} &= - m_{3} a_{2} \left(a_{3} s_{3} + l_{c3} c_{3}\right) \dot{q}_{3}" in step6
    assert "+ -" not in step6
    # what C's entries print is C: Σ_k q̇_k Γ_ijk, the groups undone
    from eomgen.present.grouping import body_masses
    from eomgen.teach.content import coriolis_terms

    dyn = eomgen.derive(model, outputs=("M", "C", "g"), simplify=False)
    book = nt.textbook_for(dyn, HANDOUT_CONFIG)
    _, christoffel, _ = named_coriolis(dyn, book)
    entries = coriolis_terms(christoffel, book.qd, body_masses(book))
    for i in range(model.dof):
        for j in range(model.dof):
            shown = sp.Add(*entries.get((i, j), [])).doit()
            assert sp.expand(shown - book.C[i, j]) == 0, (i, j)


def zero_base_parameters(model) -> set[str]:
    """The base parameters whose combination of the description's inertial parameters is zero
    for every value of its parameters."""
    form = regressor_form(model)
    pi = form.regressor.inertial_parameters()
    standard = dict(zip(form.regressor.parameter_symbols, pi))
    return {name for name, beta in zip(form.base_names, form.beta)
            if sp.expand(beta.xreplace(standard)) == 0}


def test_identically_zero_base_parameters_are_left_out(arm):
    model, dyn, book, coriolis, markdown = arm
    zero = zero_base_parameters(model)
    assert zero  # both arms have some: centres of mass on the links' x axes (MY_k = 0)
    eqs = slotine_li_equations(dyn, book, coriolis)
    assert set(eqs.zero) == zero and not zero & set(eqs.names)
    assert eqs.Y.cols == len(eqs.names) == len(eqs.beta) and all(b != 0 for b in eqs.beta)
    section = sections(markdown)["Adaptive control: the Slotine–Li regressor"]
    for name in zero:
        tex = eomgen.regressor.parameter_latex(name)
        assert f"{tex} &=" not in section and f"${tex}$" in section
    assert "zero for every value of this robot's parameters" in section
    if model.name == "planar_2link":
        assert zero == {"MY1", "MY2"}


def test_notebook_prints_the_reference_velocities_as_the_handout_does():
    model = eomgen.load(eomgen.example_path("planar_2link"))
    sl = eomgen.derive(model, outputs=("Y_SL_base", "beta"))
    qd_r, qdd_r = sl.input_symbols["qd_r"], sl.input_symbols["qdd_r"]
    dyn = eomgen.derive(model)
    assert expression_latex(dyn, qd_r[1]) == r"\dot{q}_{r,2}"
    assert expression_latex(dyn, qdd_r[0] + qd_r[0]) == r"\dot{q}_{r,1} + \ddot{q}_{r,1}"
    markdown = handout_files(model, ["md"], check=False)[0].content
    assert r"\dot{q}_{r,2}" in markdown and "qd\\_r" not in markdown
