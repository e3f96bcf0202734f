"""The LaTeX backend (``eomgen.codegen.backends.latex_backend``) and the textbook derivation it
prints for small models (``eomgen.symbolic.textbook``).

* the textbook quantities against :func:`eomgen.derive`: Σ K_i = K, Σ P_i = P,
  Σ m J_vᵀ J_v + J_ωᵀ R I Rᵀ J_ω = M, and C from the Christoffel symbols, g = ∂P/∂q
  (symbolically for the planar arm; numerically for random 2- and 3-joint arms with general
  axes, offsets, prismatic joints and branches);
* the printer's notation (compact trigonometry, dots, subscripts, numbers) and the escaping of
  every string that comes from a description;
* the documents: the planar arm's textbook entries, the program of named subexpressions for
  large robots, hostile names, determinism across hash seeds, and compilation with pdflatex.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.codegen import available_backends, make_job
from eomgen.codegen.backends.latex_backend import (
    LatexConfig, generate_latex, printing, render_document, symbol_names, textbook_for,
)
from eomgen.codegen.backends.latex_printer import (
    TEXT_ESCAPES, DerivationLatexPrinter, display_width, latex_comment, latex_escape,
    symbol_latex, written_number,
)
from eomgen.dynamics import Dynamics, joint_symbols
from eomgen.model import (
    Inertial, Joint, JointType, Link, Parameter, Transform, build_model, parameter_symbol,
)
from eomgen.robots import example_path
from eomgen.symbolic.evaluate import compile_program
from eomgen.symbolic.textbook import (
    TEXTBOOK_MAX_DOF, christoffel_symbols, description_floats, fourier_form, textbook_derivation,
)
from support import erd_robots_dir
from support import TESTS
from support.reference import planar_2link_by_hand, random_robot
from support.robots import puma_arm

ALL = ("M", "C", "g", "tau")
pytestmark = pytest.mark.filterwarnings("ignore::eomgen.errors.PhysicalConsistencyWarning")
PDFLATEX = shutil.which("pdflatex")
needs_pdflatex = pytest.mark.skipif(
    PDFLATEX is None,
    reason="pdflatex not installed (the CI script installs texlive-latex-base: "
           "apt-get install --no-install-recommends texlive-latex-base)")


@functools.cache
def dynamics(name: str) -> Dynamics:
    """Derived dynamics (M, C, g, tau) of a bundled example or of example-robot-data's UR5."""
    if name == "ur5":
        robots = erd_robots_dir()
        if robots is None:
            pytest.skip("example-robot-data is not installed")
        path = robots / "ur_description" / "urdf" / "ur5_robot.urdf"
    else:
        path = example_path(name)
    return eomgen.derive(eomgen.load(path), outputs=ALL)


@functools.cache
def document(name: str) -> str:
    [file] = generate_latex(make_job(dynamics(name)))
    return file.content


def equation(tex: str, lhs: str) -> str:
    """The right-hand side of ``lhs &= …`` in ``tex`` (continuation lines included)."""
    start = tex.index(lhs + " &= ") + len(lhs) + 4
    end = min(i for i in (tex.find("\n\\\\\n", start), tex.find("\\end{align*}", start))
              if i >= 0)
    return tex[start:end].strip()


# ----------------------------------------------------------------------------------------------
# The textbook derivation against eomgen.derive
# ----------------------------------------------------------------------------------------------


@functools.cache
def planar_book():
    return textbook_derivation(dynamics("planar_2link").model)


def test_planar_energies_sum_to_K_and_P():
    dyn, book = dynamics("planar_2link"), planar_book()
    K = sp.Add(*[body.K for body in book.bodies])
    P = sp.Add(*[body.P for body in book.bodies])
    assert sp.simplify(K - dyn.K) == 0
    assert sp.simplify(P - dyn.P) == 0
    values = dyn.model.parameter_values
    rng = np.random.default_rng(1)
    for _ in range(3):
        state = {**values, **dict(zip(dyn.q, rng.uniform(-np.pi, np.pi, 2))),
                 **dict(zip(dyn.qd, rng.normal(size=2)))}
        assert float(K.subs(state)) == pytest.approx(float(dyn.K.subs(state)), rel=1e-12)
        assert float(P.subs(state)) == pytest.approx(float(dyn.P.subs(state)), rel=1e-12,
                                                     abs=1e-12)


def test_planar_mass_matrix_is_the_sum_over_bodies():
    dyn, book = dynamics("planar_2link"), planar_book()
    M = sp.zeros(2, 2)
    for body in book.bodies:  # from the printed quantities, not from the stored shares
        R = body.rotation
        M += body.mass * body.J_v.T * body.J_v + body.J_w.T * R * body.inertia * R.T * body.J_w
    assert sp.simplify(M - dyn.M) == sp.zeros(2, 2)
    assert sp.simplify(book.M - dyn.M) == sp.zeros(2, 2)


def test_planar_christoffel_C_and_g_match_derive():
    dyn, book = dynamics("planar_2link"), planar_book()
    assert sp.simplify(book.C - dyn.C) == sp.zeros(2, 2)
    assert sp.simplify(book.g - dyn.g) == sp.zeros(2, 1)
    l1, lc2, m2 = (parameter_symbol(n) for n in ("l1", "lc2", "m2"))
    h = -l1 * lc2 * m2 * sp.sin(dyn.q[1])  # the textbook's h
    assert dict(book.christoffel) == {(0, 0, 1): h, (0, 1, 1): h, (1, 0, 0): -h}


def test_planar_kinematics_are_the_textbook():
    q1, q2 = joint_symbols(2)[0]
    l1, lc1, lc2 = (parameter_symbol(n) for n in ("l1", "lc1", "lc2"))
    link1, link2 = planar_book().bodies
    assert link1.com == sp.Matrix([lc1 * sp.cos(q1), lc1 * sp.sin(q1), 0])
    assert link2.com == sp.Matrix([l1 * sp.cos(q1) + lc2 * sp.cos(q1 + q2),
                                   l1 * sp.sin(q1) + lc2 * sp.sin(q1 + q2), 0])
    assert link2.J_w == sp.Matrix([[0, 0], [0, 0], [1, 1]])
    assert link2.links == ("link2", "tip")


@pytest.mark.parametrize("seed, n", [(0, 2), (1, 2), (5, 2), (8, 3)])
def test_random_arms_match_derive(seed, n):
    """General axes and offsets (rpy), prismatic joints, fixed links and branches: the body
    quantities are checked numerically against the program of eomgen.derive."""
    rng = np.random.default_rng(seed)
    model = random_robot(rng, n, tree=seed in (5, 8))
    book = textbook_derivation(model)
    dyn = eomgen.derive(model, simplify=False)
    reference = compile_program(dyn.program, dyn.q + dyn.qd)  # never expanded
    shares = sp.zeros(n, n)
    for body in book.bodies:
        R = body.rotation
        shares += body.mass * body.J_v.T * body.J_v + body.J_w.T * R * body.inertia * R.T * body.J_w
    ours = sp.lambdify(dyn.q + dyn.qd, [book.M, shares, book.C, book.g,
                                        sum(b.K for b in book.bodies), sum(b.P for b in book.bodies)])
    for _ in range(3):
        q, qd = rng.uniform(-np.pi, np.pi, n), rng.normal(size=n)
        M, M_shares, C, g, K, P = (np.array(x, dtype=float) for x in ours(*q, *qd))
        theirs = reference(*q, *qd)
        for a, b in [(M, theirs["M"]), (M_shares, theirs["M"]), (C, theirs["C"]), (g, theirs["g"]),
                     (K, qd @ theirs["M"] @ qd / 2), (P, theirs["P"][0, 0])]:
            assert np.allclose(a, b, rtol=1e-9, atol=1e-9 * max(1.0, np.abs(b).max())), (a, b)


def test_textbook_refuses_large_models():
    with pytest.raises(ValueError, match="at most 3 joints"):
        textbook_derivation(dynamics("puma560_dh").model)
    assert TEXTBOOK_MAX_DOF == 3


def test_fourier_form_is_canonical():
    q1, q2 = sp.symbols("q1 q2")
    s1, c1, s2, c2 = sp.sin(q1), sp.cos(q1), sp.sin(q2), sp.cos(q2)
    assert fourier_form(s1**2 + c1**2, (q1, q2)) == 1
    assert fourier_form(c1 * c2 - s1 * s2, (q1, q2)) == sp.cos(q1 + q2)
    assert fourier_form(s1 * c2 - c1 * s2, (q1, q2)) == sp.sin(q1 - q2)
    assert fourier_form(2 * s2 * c2, (q1, q2)) == sp.sin(2 * q2)
    a = sp.Symbol("a")
    assert fourier_form(a * sp.cos(q1 + q2) * sp.cos(a), (q1, q2)) == a * sp.cos(a) * sp.cos(q1 + q2)


def test_christoffel_symbols_use_the_symmetry():
    q1, q2 = sp.symbols("q1 q2")
    M = sp.Matrix([[3 + 2 * sp.cos(q2), 1 + sp.cos(q2)], [1 + sp.cos(q2), 1]])
    symbols = dict(christoffel_symbols(M, (q1, q2)))
    assert all(j <= k for _, j, k in symbols)
    assert symbols[(0, 0, 1)] == -sp.sin(q2)
    assert symbols[(1, 0, 0)] == sp.sin(q2)


# ----------------------------------------------------------------------------------------------
# The printer and the escaping
# ----------------------------------------------------------------------------------------------


def printer(n: int = 2, **settings) -> DerivationLatexPrinter:
    q, qd, qdd = joint_symbols(n)
    names = {}
    for k in range(n):
        names[q[k]] = f"q_{{{k + 1}}}"
        names[qd[k]] = rf"\dot{{q}}_{{{k + 1}}}"
        names[qdd[k]] = rf"\ddot{{q}}_{{{k + 1}}}"
    return DerivationLatexPrinter({"joint_positions": q, "symbol_names": names, **settings})


def test_compact_trigonometry():
    p = printer(10)
    q = joint_symbols(10)[0]
    assert p.doprint(sp.sin(q[0])) == "s_{1}"
    assert p.doprint(sp.cos(q[0] + q[1])) == "c_{12}"
    assert p.doprint(sp.cos(q[2] + q[1] + q[0])) == "c_{123}"
    assert p.doprint(sp.cos(q[0] + q[9])) == "c_{1,10}"
    assert p.doprint(sp.sin(q[1]) ** 2) == "s_{2}^{2}"
    assert p.doprint(sp.cos(2 * q[1])) == r"\cos{\left(2 q_{2} \right)}"
    assert p.doprint(sp.cos(q[0] - q[1])) == r"\cos{\left(q_{1} - q_{2} \right)}"
    assert printer(2, compact_trig=False).doprint(sp.sin(q[0])) == r"\sin{\left(q_{1} \right)}"


def test_joint_symbols_parameters_and_numbers():
    q, qd, qdd = joint_symbols(2)
    p = printer(2)
    assert p.doprint(qd[0] * qdd[1]) == r"\dot{q}_{1} \ddot{q}_{2}"
    assert p.doprint(parameter_symbol("lc1") * parameter_symbol("m1")) == "l_{c1} m_{1}"
    assert p.doprint(sp.Float(2.517506271375) * q[0]) == "2.517506271375 q_{1}"
    assert printer(2, float_digits=6).doprint(sp.Float(2.517506271375)) == "2.51751"
    assert p.doprint(sp.Float(3.2e-5)) == r"3.2 \cdot 10^{-5}"
    assert p.doprint(sp.pi / 2) == r"\frac{\pi}{2}"


def read_latex_number(tex: str) -> float:
    """The float a printed number denotes (``-1.5 \\cdot 10^{-5}``, ``10^{6}``, ``0.3``), parsed
    independently of the printer."""
    match = re.fullmatch(r"(-?)(?:([0-9.]+)(?: \\cdot )?)?(?:10\^\{(-?[0-9]+)\})?", tex)
    assert match and (match[2] or match[3]), tex
    return float(f"{match[1]}{match[2] or '1'}e{match[3] or 0}")


@pytest.mark.parametrize("value", [
    1 / 3, 0.1 + 0.2, 2 / 3 * 1e-9, -7 / 3 * 1e22, 0.3, 123456.78901234567, 1e-4, 5e-324,
    1.7976931348623157e308, -0.0078125, 6.02214076e23, 100.0, 0.0,
])
def test_floats_print_the_shortest_decimal_that_reads_back(value):
    """Every float prints as the shortest decimal that reads back as the same double: the
    digits of repr (Python's shortest round-trip algorithm), no rounding noise, no 17th digit
    that repr would not need."""
    tex = printer(1).doprint(sp.Float(value))
    assert read_latex_number(tex) == value
    digits = re.sub(r"\\cdot 10\^\{-?[0-9]+\}|10\^\{-?[0-9]+\}|[^0-9]", "", tex).strip("0")
    assert len(digits) == len(repr(abs(value)).split("e")[0].replace(".", "").strip("0"))


def test_numbers_as_a_description_wrote_them():
    q = joint_symbols(1)[0][0]
    p = printer(1)
    assert p.doprint(sp.Float(0.3)) == "0.3"
    assert p.doprint(sp.Float(1 / 3)) == "0.3333333333333333"
    assert p.doprint(sp.Float(0.1) + sp.Float(0.2)) == "0.30000000000000004"  # another double
    assert p.doprint(sp.Float(1.0) * q) == "q_{1}" and p.doprint(sp.Float(-1.0) * q) == "- q_{1}"
    assert p.doprint(sp.Rational(1, 3) * q) == r"\frac{q_{1}}{3}"
    assert p.doprint(sp.Rational(1, 3)) == r"\frac{1}{3}"
    assert p.doprint(sp.Float(2.0) * q) == "2 q_{1}"
    # with the description's floats known, computed ones lose their rounding noise only
    written = printer(1, written_floats=frozenset({0.1, 0.2, 1 / 3}))
    assert written.doprint(sp.Float(0.1 + 0.2)) == "0.3"
    assert written.doprint(sp.Float(1 / 3)) == "0.3333333333333333"
    assert written.doprint(sp.Float(0.1 * 0.2)) == "0.02"
    assert written_number(1 / 12) == sp.Rational(1, 12)
    assert written_number(0.4318) == sp.Float(0.4318) and written_number(3.0) == 3


def _long_numbers(tex: str) -> set[float]:
    """The numbers of ``tex`` printed with 16 or 17 significant digits."""
    found = set()
    for match in re.finditer(r"(?<![0-9_{])([0-9]+\.[0-9]+)(?: \\cdot 10\^\{(-?[0-9]+)\})?", tex):
        if len(match[1].replace(".", "").strip("0")) >= 16:
            found.add(float(f"{match[1]}e{match[2] or 0}"))
    return found


@pytest.mark.parametrize("name", ["elbow_rrr", "puma560_dh", "puma_arm"])
def test_documents_show_no_rounding_noise(name):
    """The elbow arm (textbook), the PUMA 560 (program) and its arm with the wrist locked
    (textbook over floats): no number with 16-17 digits except the description's own, and
    the elbow arm's lengths print as written."""
    dyn = _puma_arm() if name == "puma_arm" else dynamics(name)
    text = render_document(make_job(dyn))
    assert "0000000" not in text and "9999999" not in text
    assert _long_numbers(text) <= description_floats(dyn.model)
    if name == "elbow_rrr":
        assert "$a_{3}$ & $0.3$" in text and "$I_{1}$ & $0.01$" in text


@pytest.mark.parametrize("name, tex", [
    ("m1", "m_{1}"), ("lc1", "l_{c1}"), ("I1", "I_{1}"), ("g", "g"), ("alpha2", r"\alpha_{2}"),
    ("Gamma1_2_3", r"\Gamma_{1,2,3}"), ("M1_2", "M_{1,2}"), ("R2_00", "R_{2,00}"),
    ("Iw2_22", "I_{w2,22}"), ("s1_", "s_{1}'"), ("mass", r"\mathrm{mass}"),
    ("link1", r"\mathrm{link}_{1}"), ("m_link", r"\textrm{m\_link}"), ("x__y", r"\textrm{x\_\_y}"),
])
def test_symbol_names(name, tex):
    assert symbol_latex(name) == tex


def test_symbol_names_are_distinct():
    names = ["M12", "M1_2", "M1_2_", "M_1_2", "lc1", "l1", "lc", "Gamma123", "Gamma1_2_3", "s1",
             "s1_", "s_1", "mass1", "mass_1", "mass", "ma1", "m1", "Rh2_0", "R2_0", "h2_0", "x",
             "xx", "x_", "x1", "x11", "x1_1", "pi1", "p1", "pc1", "p1c"]
    assert len({symbol_latex(n) for n in names}) == len(names)


def test_parameters_named_like_the_notation_print_as_text():
    links = [Link("base"), Link("a", Inertial(parameter_symbol("K1"))),
             Link("b", Inertial(parameter_symbol("c12") + parameter_symbol("M1_2")))]
    joints = [Joint("j1", JointType.REVOLUTE, "base", "a"),
              Joint("j2", JointType.PRISMATIC, "a", "b", axis=(1, 0, 0))]
    model = build_model("<test>", "clash", links, joints,
                        parameters=[Parameter(parameter_symbol(n), 1.0) for n in ("K1", "c12", "M1_2")])
    job = make_job(eomgen.derive(model, outputs=ALL))
    names = symbol_names(job.dynamics)
    assert names[parameter_symbol("K1")] == r"\textrm{K1}"
    assert names[parameter_symbol("c12")] == r"\textrm{c12}"
    assert names[parameter_symbol("M1_2")] == r"\textrm{M1\_2}"
    tex = render_document(job)
    assert r"\textrm{K1}" in tex and "K_{1} &= " in tex


def test_long_sums_break_into_lines():
    q = joint_symbols(3)[0]
    terms = sp.Add(*[sp.Symbol(f"m{k}", real=True) * sp.cos(q[k % 3]) * sp.sin(q[(k + 1) % 3])
                     for k in range(1, 30)])
    lines = printer(3).print_lines(sp.Symbol("g", real=True) * terms, 60)
    assert len(lines) > 3
    assert lines[0].startswith(r"g \bigl(") and lines[-1].endswith(r"\bigr)")
    assert all(display_width(line) <= 60 for line in lines)
    assert all(line.startswith(("+ ", "- ")) for line in lines[1:])


def test_broken_sums_keep_their_signs():
    a, b, c, x = (sp.Symbol(n, real=True) for n in "abcx")
    p = printer()
    assert p.print_sum_lines([x, -a - b], 80) == [r"x + \left(- a - b\right)"]
    assert p.print_sum_lines([x, -a - b - c], 3) == ["x - a", "- b", "- c"]
    assert p.print_sum_lines([-x * (a + b)], 3) == [r"- x \bigl(a", r"+ b\bigr)"]


HOSTILE = [
    'a"); import os #', r"\input{/etc/passwd}", "_ & % $ # { } ~ ^ \\", "[x]*<y>|é",
    "line\nbreak\\end{document}", "\\\\*[3pt]", "}\\catcode`\\%=12 {", "%\\write18{touch pwned}",
]


#: What each character special to TeX must become (independent of the printer's own table).
EXPECTED_ESCAPES = {
    "\\": r"\textbackslash{}", "{": r"\{", "}": r"\}", "$": r"{\char36}", "&": r"\&",
    "#": r"\#", "%": r"\%", "_": r"\_", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}",
    "[": "{[}", "]": "{]}", "*": "{*}", "<": r"\textless{}", ">": r"\textgreater{}",
    "|": r"\textbar{}",
}


def test_escape_table():
    assert TEXT_ESCAPES == EXPECTED_ESCAPES
    assert latex_escape("".join(EXPECTED_ESCAPES)) == "".join(EXPECTED_ESCAPES.values())
    assert latex_escape("é\n\t") == r"{[}U+00E9{]}\textbackslash{}n\textbackslash{}t"


@pytest.mark.parametrize("text", HOSTILE)
def test_escaped_text_has_no_active_characters(text):
    escaped = latex_escape(text)
    rest = escaped
    for sequence in sorted(EXPECTED_ESCAPES.values(), key=len, reverse=True):
        rest = rest.replace(sequence, "")
    rest = re.sub(r"\{\[\}U\+[0-9A-F]{4,6}\{\]\}", "", rest)  # non-ASCII code points
    assert not set(rest) & set("\\{}$&#%_~^[]*\n\r"), (escaped, rest)
    assert "\n" not in latex_comment(text) and latex_comment(text).startswith("% ")


# ----------------------------------------------------------------------------------------------
# The documents
# ----------------------------------------------------------------------------------------------


def test_latex_backend_is_registered():
    backend = available_backends()["latex"]
    job = make_job(dynamics("planar_2link"))
    [file] = backend.generate(job)
    assert file.name == "planar_2link.tex" and file.golden
    assert file.content == document("planar_2link")


def test_planar_document_has_the_textbook_entries_in_compact_form():
    tex = document("planar_2link")
    assert tex.startswith("% Generated by eomgen ")
    assert all(line.startswith("% ") for line in tex.splitlines()[:3])
    assert "do not edit by hand" in tex and r"\texttt{planar\_2link}" in tex
    M11 = equation(tex, "M_{1,1}")
    assert "c_{2}" in M11 and "m_{1} l_{c1}^{2}" in M11 and r"\cos" not in M11  # grouped by mass
    assert "s_{2}" in equation(tex, "C_{1,1}") and "s_{2}" in equation(tex, "C_{1,2}")
    assert equation(tex, "C_{2,2}") == "0"
    assert "c_{12}" in equation(tex, "g_{1}") and "c_{12}" in equation(tex, "g_{2}")
    assert "s_{12}" in equation(tex, "p_{c2}")
    assert r"\Gamma_{1,1,2} = \Gamma_{1,2,1}" in tex
    assert r"\ddot{q}_{1}" in equation(tex, r"\tau_{1}")
    for section in ("Kinematics", "Energies", "Mass matrix", "Christoffel symbols",
                    "Coriolis matrix", "Gravity vector", "Equations of motion"):
        assert rf"\section{{{section}}}" in tex
    assert "K_{1} &= " in tex and "P_{2} &= " in tex
    assert r"\begin{longtable}" in tex and "joint2 & revolute & link1 & link2" in tex
    assert "A large model" not in tex


def test_planar_document_prints_the_regressor_as_derived_by_hand():
    """τ = Y π with the columns named: every non-zero entry of Y is the hand derivation
    (reference.planar_2link_by_hand, printed in the document's notation), the zero columns
    are listed, and the base parameters are the hand grouping, own parameter first."""
    from eomgen.regressor import regressor_form

    tex = document("planar_2link")
    hand, q, _ = planar_2link_by_hand()
    dyn = dynamics("planar_2link")
    form = regressor_form(dyn.model)
    p = printing(dyn, LatexConfig(), compact_trig=True, extra_names=form.latex_names)
    printed = 0
    for name, rows in hand.items():
        column = name.rstrip("0123456789")
        for i, entry in enumerate(rows, start=1):
            lhs = rf"\bigl[Y\bigr]_{{{i},\,\mathrm{{{column}}}_{{{name[-1]}}}}} &= "
            if entry == 0:
                assert lhs not in tex
                continue
            written = sp.factor_terms(fourier_form(entry, q), sign=False)
            assert lhs + " ".join(p.printer.print_lines(written, 10 ** 6)) in tex, name
            printed += 1
    assert tex.count(r"\bigl[Y\bigr]_") == printed == 10
    assert r"\pi = \left(\mathrm{MX}_{1}, \mathrm{MY}_{1}, \mathrm{ZZ}_{1}, \mathrm{M}_{2}, " in tex
    assert r"$\mathrm{M}_{1}, \mathrm{MZ}_{1}, \mathrm{XX}_{1}," in tex  # zero columns
    assert r"\mathrm{MX}_{1}^{R} &= \mathrm{MX}_{1} + \mathrm{M}_{2} l_{1}" + "\n" in tex
    assert r"\mathrm{ZZ}_{1}^{R} &= \mathrm{ZZ}_{1} + \mathrm{M}_{2} l_{1}^{2}" + "\n" in tex
    assert r"\mathrm{MY}_{1} &=" not in tex  # not grouped: named in β only
    assert r"\section{Linear in the parameters: the regressor}" in tex


def test_large_documents_skip_the_regressor_with_a_sentence():
    tex = document("puma560_dh")
    assert r"\section{Linear in the parameters}" in tex
    assert "written out for teaching-sized models only" in tex
    assert r"\bigl[Y\bigr]" not in tex and "Base parameters" not in tex


def test_dh_document_has_the_table_and_the_program():
    tex = document("puma560_dh")
    assert textbook_for(dynamics("puma560_dh")) is None
    assert r"\subsection*{Denavit--Hartenberg table}" in tex and "Convention: standard." in tex
    assert r"joint2 & revolute & $0.4318$ & $0$ & $0$ & $0$ \\" in tex
    assert r"$\frac{\pi}{2}$" in tex
    assert "A large model" in tex and r"\section{Kinematics}" not in tex
    assert r"s_{1} &= \sin{\left(q_{1} \right)}" in tex
    # C by Echeandia and Wensing's recursion: body velocities V, no Christoffel symbols
    assert r"V_{2,0} &= " in tex and r"\Gamma_{" not in tex and r"\tau_{6} &= " in tex
    assert "not printed" not in tex


def test_program_is_capped():
    tex = render_document(make_job(dynamics("puma560_dh")), LatexConfig(max_program_lines=250))
    assert "are not printed" in tex and "Coriolis matrix (" not in tex
    assert "Further subexpressions of the Coriolis matrix" not in tex
    lines = [l for l in tex.splitlines() if " &= " in l]
    assert len(lines) < 400


def named_model(robot: str, names: list[str]):
    """A two-joint arm whose robot, link and joint names are taken from ``names``."""
    inertial = Inertial(1.5, (0.1, 0.02, 0), ((0.1, 0, 0), (0, 0.2, 0), (0, 0, 0.25)))
    l1, l2, tool, extra, j1, j2, fixed, fixed2 = names
    links = [Link("base"), Link(l1, inertial), Link(l2, inertial), Link(tool), Link(extra)]
    joints = [
        Joint(j1, JointType.REVOLUTE, "base", l1, Transform.from_xyz_rpy((0, 0, 0.1), (0.3, 0, 0))),
        Joint(j2, JointType.REVOLUTE, l1, l2, Transform.from_xyz_rpy((0.4, 0, 0)), (0, 1, 0)),
        Joint(fixed, JointType.FIXED, l2, tool, Transform.from_xyz_rpy((0.3, 0, 0))),
        Joint(fixed2, JointType.FIXED, tool, extra),
    ]
    return build_model("arm.yaml", robot, links, joints,
                       info={"description": names[0] + " " + robot})


def test_hostile_names_only_appear_escaped():
    """Every name of the hostile arm appears in its document exactly where the placeholder name
    of an otherwise identical arm appears in that one, escaped."""
    hostile_robot = r"\input{/etc/passwd} $x$ % #"
    placeholders = [f"name{k}" for k in range(len(HOSTILE))]
    hostile_job = make_job(eomgen.derive(named_model(hostile_robot, HOSTILE), outputs=ALL))
    plain_job = make_job(eomgen.derive(named_model("robotname", placeholders), outputs=ALL))
    [hostile] = generate_latex(hostile_job)
    [plain] = generate_latex(plain_job)
    assert re.fullmatch(r"[a-z][a-z0-9_]*\.tex", hostile.name)
    text = hostile.content
    assert r"\input{" not in text.replace(r"\textbackslash{}input\{", "")
    assert r"\textbackslash{}input\{/etc/passwd\}" in text
    assert "\\write18" not in text and "\\catcode" not in text
    for name in HOSTILE + [hostile_robot]:
        assert name not in text
    replaced = text.replace(latex_escape(hostile_robot), "robotname")
    for name, placeholder in sorted(zip(HOSTILE, placeholders),
                                    key=lambda pair: -len(latex_escape(pair[0]))):
        replaced = replaced.replace(latex_escape(name), placeholder)
    assert replaced == plain.content


def _puma_arm() -> Dynamics:
    """The PUMA 560 with its wrist locked: a 3-joint arm with float parameters (textbook)."""
    return eomgen.derive(puma_arm(), outputs=ALL, simplify=False)


@pytest.mark.slow
def test_documents_are_deterministic_across_hash_seeds():
    """Same input, byte-identical output: twice in this process, and in a fresh interpreter
    with another hash seed (no set or dict order leaks into the text)."""
    script = (
        "import hashlib, sys, warnings\n"
        "warnings.simplefilter('ignore')\n"
        "sys.path.insert(0, %r)\n"
        "from support.robots import puma_arm\n"
        "import eomgen\n"
        "from eomgen.codegen import make_job\n"
        "from eomgen.codegen.backends.latex_backend import render_document\n"
        "for name in ('planar_2link', 'puma560_dh'):\n"
        "    dyn = eomgen.derive(eomgen.load(eomgen.example_path(name)), "
        "outputs=('M', 'C', 'g', 'tau'))\n"
        "    print(hashlib.sha256(render_document(make_job(dyn)).encode()).hexdigest())\n"
        "arm = eomgen.derive(puma_arm(), outputs=%r, simplify=False)\n"
        "print(hashlib.sha256(render_document(make_job(arm)).encode()).hexdigest())\n"
    ) % (str(TESTS), ALL)
    expected = []
    for name in ("planar_2link", "puma560_dh"):
        again = render_document(make_job(eomgen.derive(eomgen.load(example_path(name)), outputs=ALL)))
        assert again == document(name)
        expected.append(hashlib.sha256(again.encode()).hexdigest())
    arm = render_document(make_job(_puma_arm()))
    assert arm == render_document(make_job(_puma_arm())) and r"\section{Kinematics}" in arm
    expected.append(hashlib.sha256(arm.encode()).hexdigest())
    env = {**os.environ, "PYTHONHASHSEED": "4242", "PYTHONWARNINGS": "ignore"}
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                         text=True, check=True, timeout=300)
    assert out.stdout.split() == expected


# ----------------------------------------------------------------------------------------------
# Compilation with pdflatex
# ----------------------------------------------------------------------------------------------


def compile_tex(text: str, directory: Path, stem: str = "doc") -> tuple[Path, float]:
    """Run pdflatex (no shell escape, stop at the first error) on ``text``; return the PDF and
    the seconds it took."""
    source = directory / f"{stem}.tex"
    source.write_text(text)
    start = time.perf_counter()
    result = subprocess.run(
        [PDFLATEX, "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape", source.name],
        cwd=directory, capture_output=True, text=True, timeout=120)
    seconds = time.perf_counter() - start
    log = directory / f"{stem}.log"
    tail = log.read_text(errors="replace")[-3000:] if log.exists() else result.stdout[-3000:]
    assert result.returncode == 0, tail
    pdf = directory / f"{stem}.pdf"
    assert pdf.exists() and pdf.stat().st_size > 1000
    return pdf, seconds


def pdf_text(pdf: Path) -> str | None:
    if shutil.which("pdftotext") is None:
        return None
    return subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True,
                          check=True, timeout=60).stdout


@needs_pdflatex
@pytest.mark.parametrize("name, title", [
    ("planar_2link", "Equations of motion of planar"),
    ("puma560_dh", "Equations of motion of puma560"),
    ("ur5", "Equations of motion of ur5"),
])
def test_documents_compile_with_pdflatex(tmp_path, name, title):
    pdf, seconds = compile_tex(document(name), tmp_path)
    assert seconds < 60, f"pdflatex took {seconds:.1f} s"
    text = pdf_text(pdf)
    if text is not None:
        assert title in text and "Equations of motion" in text


@needs_pdflatex
@pytest.mark.slow
def test_general_arm_textbook_document_compiles(tmp_path):
    model = replace(random_robot(np.random.default_rng(0), 2), name="general_arm")
    job = make_job(eomgen.derive(model, outputs=ALL, simplify=False))
    text = render_document(job)
    assert r"\section{Christoffel symbols}" in text
    assert not re.search(r"10\^\{-(1[0-9]|[2-9][0-9])\}", text)  # no rounding noise printed
    compile_tex(text, tmp_path)


@needs_pdflatex
def test_hostile_document_compiles_and_shows_the_names(tmp_path):
    job = make_job(eomgen.derive(named_model(r"\input{/etc/passwd} $x$ % #", HOSTILE), outputs=ALL))
    pdf, _ = compile_tex(render_document(job), tmp_path)
    assert not (tmp_path / "pwned").exists()
    text = pdf_text(pdf)
    if text is not None:
        assert r"\input{/etc/passwd} $x$ % #" in text
        assert 'a”); import os #' in text or 'a"); import os #' in text


def test_float_one_coefficients_are_not_printed():
    """Rotation matrices from numeric descriptions carry 1.0 and -1.0 factors: they print as
    nothing and as a minus sign, not as '1 \\cos' (values equal, so no information is lost)."""
    q1, q2, a, b = sp.symbols("q1 q2 a b")
    p = DerivationLatexPrinter({"joint_positions": (q1, q2)})
    assert p.doprint(1.0 * sp.cos(q1 - q2)) == r"\cos{\left(q_{1} - q_{2} \right)}"
    assert p.doprint(-1.0 * sp.sin(q1) * a) == r"- a s_{1}"
    assert p.doprint(2.5 * a) == "2.5 a"


def test_rounded_digits_remain_an_option():
    """``LatexConfig(float_digits=6)``: the shorter, lossy page of earlier versions, and the
    document says which rule it used."""
    job = make_job(dynamics("puma560_dh"))
    rounded = render_document(job, LatexConfig(float_digits=6))
    full = render_document(job)
    assert "numbers are shown with 6 significant digits" in rounded
    assert "shortest decimals that read back as the same doubles" in full
    assert "1.03119 R_{2,00}" in rounded and "1.03118515 R_{2,00}" in full


@pytest.mark.slow
def test_program_legend_reads_tags_not_names():
    """The intermediates of the world-frame Lagrangian programs carry a Tag set where they are
    defined; the document's legend groups by the tags, so renaming every intermediate to a
    neutral name (x0, x1, …, tags kept) leaves the legend as it was."""
    from support.reference import random_robot

    from eomgen.codegen.backends.latex_backend import (LatexConfig, PROGRAM_NAMES, printing,
                                                       program_sections)
    from eomgen.symbolic.program import Assignment, Program

    dyn = eomgen.derive(random_robot(np.random.default_rng(0), 3), outputs=("M", "C", "g"))
    tags = dyn.program.tags()
    assert len(tags) >= 20  # the kinematics and composite inertias, at least
    for symbol, tag in tags.items():
        if tag.family == "P":  # the potential energy, a scalar of the whole robot
            continue
        assert tag.family in PROGRAM_NAMES, tag
        assert tag.index and tag.index[0] >= 1, (symbol, tag)
    config = LatexConfig()
    legend = program_sections(dyn, config, printing(dyn, config, False))["legend"]
    assert len(legend) >= 10

    rename = {s: sp.Symbol(f"x{k}", real=True) for k, (s, _) in enumerate(dyn.program.assignments)}
    program = Program(
        tuple(Assignment(rename[s], e.xreplace(rename), tags.get(s))
              for s, e in dyn.program.assignments),
        tuple((name, m.xreplace(rename)) for name, m in dyn.program.outputs))
    renamed = replace(dyn, program=program)
    again = program_sections(renamed, config, printing(renamed, config, False))["legend"]
    assert [meaning for _, meaning in again] == [meaning for _, meaning in legend]
    assert [tex for tex, _ in again] != [tex for tex, _ in legend]  # printed with the new names


@pytest.mark.parametrize("robot, outputs", [
    ("puma560_dh", ("M", "C", "g", "tau")),        # body-frame CRBA, Echeandia–Wensing, NE
    ("planar_2link", ("M", "C", "g", "tau", "qdd_aba", "h", "MCg")),
    ("scara_rrp", ("M", "C", "g", "tau", "qdd_aba", "h")),
])
def test_every_intermediate_has_a_tag_with_a_legend_line(robot, outputs):
    """Every recursion eomgen builds M, C, g, τ, the ABA and h with tags each intermediate where
    it is defined (the tag, not the name, says what it is), and the document's legend has a
    line for every family; the PUMA's document names the Newton–Euler and CRBA quantities."""
    from eomgen.codegen.backends.latex_backend import (LatexConfig, PROGRAM_NAMES, printing,
                                                       program_sections)

    dyn = eomgen.derive(eomgen.load(eomgen.example_path(robot)), outputs=outputs,
                        simplify=False)
    tags = dyn.program.tags()
    untagged = [s.name for s, _ in dyn.program.assignments if s not in tags]
    assert not untagged, untagged[:10]
    assert {t.family for t in tags.values()} - {"P"} <= set(PROGRAM_NAMES)
    if robot == "puma560_dh":
        config = LatexConfig()
        legend = [meaning for _, meaning in
                  program_sections(dyn, config, printing(dyn, config, False))["legend"]]
        for family in ("a", "n", "Icb", "Fbody", "V", "Fa"):  # NE (g), CRBA (M), EW (C)
            assert PROGRAM_NAMES[family] in legend, family
