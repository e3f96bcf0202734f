"""The bundled teaching arms (elbow RRR, SCARA RRP, Stanford-type RRP, cylindrical RPP, PUMA 560
waist-shoulder-elbow): M, C, g against closed forms derived by hand, their readable printed
form, and ``Dynamics.lambdify``.

The references are written here without eomgen: for each arm, the forward kinematics by hand
(world centre-of-mass positions p_ck, body axes R_k and the world axes of the revolute joints
moving body k, from the standard DH tables in the YAML files) and the Lagrangian method of
Spong, Hutchinson & Vidyasagar, "Robot Modeling and Control" (Wiley 2006), chapter "Dynamics"
(Euler-Lagrange equations): M = Σ_k m_k J_vkᵀ J_vk + J_ωkᵀ R_k I_k R_kᵀ J_ωk with
J_vk = ∂p_ck/∂q, Christoffel symbols c_ijk = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i),
g = ∂P/∂q with P = Σ m_k g z_ck. For four arms M and g are also written in closed form (the
forms in the YAML files' headers, derived by hand from the kinetic energy of each link) and
checked against that reference, so the closed forms themselves are checked too.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.robots import example_path
from support import load_module

Q = sp.symbols("q1:4", real=True)
QD = sp.symbols("qd1:4", real=True)
q1, q2, q3 = Q
s1, c1, s2, c2 = sp.sin(q1), sp.cos(q1), sp.sin(q2), sp.cos(q2)
s3, c3 = sp.sin(q3), sp.cos(q3)
s23, c23 = sp.sin(q2 + q3), sp.cos(q2 + q3)
Z0 = sp.Matrix([0, 0, 1])
ZERO = sp.zeros(3, 1)


def P(*names):
    return sp.symbols(names, real=True)


def column(*xs):
    return sp.Matrix(xs)


def diag(x=0, y=0, z=0):
    return sp.diag(x, y, z)


def axes(x, y, z):
    return sp.Matrix.hstack(x, y, z)


def lagrange(bodies, gravity_symbol):
    """M, C, g of bodies ``(m, p_c, R, I, J_w columns)`` (I about the centre of mass in R's
    axes), gravity ``-gravity_symbol`` along world z."""
    n = 3
    M = sp.zeros(n, n)
    potential = 0
    for m, p, R, I, omega in bodies:
        J_v = p.jacobian(Q)
        J_w = sp.Matrix.hstack(*omega)
        M += m * J_v.T * J_v + J_w.T * R * I * R.T * J_w
        potential += m * gravity_symbol * p[2]
    g = sp.Matrix([sp.diff(potential, x) for x in Q])
    C = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            C[i, j] = sum((sp.diff(M[i, j], Q[k]) + sp.diff(M[i, k], Q[j])
                           - sp.diff(M[j, k], Q[i])) / 2 * QD[k] for k in range(n))
    return M, C, g


def elbow():
    d1, a2, lc2, lc3, m1, m2, m3, I1, Ix2, Iy2, Iz2, Ix3, Iy3, Iz3, g = P(
        "d1", "a2", "lc2", "lc3", "m1", "m2", "m3", "I1", "Ix2", "Iy2", "Iz2", "Ix3", "Iy3",
        "Iz3", "g")
    z1 = column(s1, -c1, 0)
    x2, y2 = column(c1 * c2, s1 * c2, s2), column(-c1 * s2, -s1 * s2, c2)
    x3, y3 = column(c1 * c23, s1 * c23, s23), column(-c1 * s23, -s1 * s23, c23)
    base = column(0, 0, d1)
    bodies = [
        (m1, base, axes(column(c1, s1, 0), Z0, z1), diag(y=I1), [Z0, ZERO, ZERO]),
        (m2, base + lc2 * x2, axes(x2, y2, z1), diag(Ix2, Iy2, Iz2), [Z0, z1, ZERO]),
        (m3, base + a2 * x2 + lc3 * x3, axes(x3, y3, z1), diag(Ix3, Iy3, Iz3), [Z0, z1, z1]),
    ]
    closed_M = sp.Matrix([
        [I1 + Ix2 * s2**2 + Iy2 * c2**2 + m2 * lc2**2 * c2**2 + Ix3 * s23**2 + Iy3 * c23**2
         + m3 * (a2 * c2 + lc3 * c23)**2, 0, 0],
        [0, Iz2 + Iz3 + m2 * lc2**2 + m3 * (a2**2 + lc3**2 + 2 * a2 * lc3 * c3),
         Iz3 + m3 * (lc3**2 + a2 * lc3 * c3)],
        [0, Iz3 + m3 * (lc3**2 + a2 * lc3 * c3), Iz3 + m3 * lc3**2]])
    closed_g = sp.Matrix([0, g * (m2 * lc2 + m3 * a2) * c2 + g * m3 * lc3 * c23,
                          g * m3 * lc3 * c23])
    return bodies, g, closed_M, closed_g


def scara():
    d1, a1, a2, lc1, lc2, m1, m2, m3, I1, I2, I3, g = P(
        "d1", "a1", "a2", "lc1", "lc2", "m1", "m2", "m3", "I1", "I2", "I3", "g")
    c12, s12 = sp.cos(q1 + q2), sp.sin(q1 + q2)
    o1 = column(a1 * c1, a1 * s1, d1)
    R1 = axes(column(c1, s1, 0), column(-s1, c1, 0), Z0)
    R2 = axes(column(c12, s12, 0), column(s12, -c12, 0), -Z0)  # alpha2 = pi: z2 points down
    bodies = [
        (m1, column(lc1 * c1, lc1 * s1, d1), R1, diag(z=I1), [Z0, ZERO, ZERO]),
        (m2, o1 + lc2 * column(c12, s12, 0), R2, diag(z=I2), [Z0, Z0, ZERO]),
        (m3, o1 + a2 * column(c12, s12, 0) - q3 * Z0, R2, diag(z=I3), [Z0, Z0, ZERO]),
    ]
    M12 = I2 + I3 + m2 * (lc2**2 + a1 * lc2 * c2) + m3 * (a2**2 + a1 * a2 * c2)
    closed_M = sp.Matrix([
        [I1 + I2 + I3 + m1 * lc1**2 + m2 * (a1**2 + lc2**2 + 2 * a1 * lc2 * c2)
         + m3 * (a1**2 + a2**2 + 2 * a1 * a2 * c2), M12, 0],
        [M12, I2 + I3 + m2 * lc2**2 + m3 * a2**2, 0],
        [0, 0, m3]])
    return bodies, g, closed_M, sp.Matrix([0, 0, -m3 * g])


def stanford():
    d1, lc3, m2, m3, I1, Ix2, Iy2, Iz2, Ix3, Iy3, Iz3, g = P(
        "d1", "lc3", "m2", "m3", "I1", "Ix2", "Iy2", "Iz2", "Ix3", "Iy3", "Iz3", "g")
    z1 = column(-s1, c1, 0)
    x2, z2 = column(c1 * c2, s1 * c2, -s2), column(c1 * s2, s1 * s2, c2)
    R2 = axes(x2, z1, z2)
    base = column(0, 0, d1)
    r = q3 - lc3
    bodies = [
        (1, base, axes(column(c1, s1, 0), -Z0, z1), diag(y=I1), [Z0, ZERO, ZERO]),
        (m2, base, R2, diag(Ix2, Iy2, Iz2), [Z0, z1, ZERO]),
        (m3, base + r * z2, R2, diag(Ix3, Iy3, Iz3), [Z0, z1, ZERO]),
    ]
    closed_M = sp.diag(I1 + (Ix2 + Ix3) * s2**2 + (Iz2 + Iz3) * c2**2 + m3 * r**2 * s2**2,
                       Iy2 + Iy3 + m3 * r**2, m3)
    return bodies, g, closed_M, sp.Matrix([0, -g * m3 * r * s2, g * m3 * c2])


def cylindrical():
    d1, lc3, m2, m3, I1, Iy2, Iy3, g = P("d1", "lc3", "m2", "m3", "I1", "Iy2", "Iy3", "g")
    x, z2 = column(c1, s1, 0), column(-s1, c1, 0)
    R2 = axes(x, -Z0, z2)
    carriage = column(0, 0, d1 + q2)
    bodies = [
        (1, column(0, 0, d1), axes(x, column(-s1, c1, 0), Z0), diag(z=I1), [Z0, ZERO, ZERO]),
        (m2, carriage, R2, diag(y=Iy2), [Z0, ZERO, ZERO]),
        (m3, carriage + (q3 - lc3) * z2, R2, diag(y=Iy3), [Z0, ZERO, ZERO]),
    ]
    closed_M = sp.diag(I1 + Iy2 + Iy3 + m3 * (q3 - lc3)**2, m2 + m3, m3)
    return bodies, g, closed_M, sp.Matrix([0, g * (m2 + m3), 0])


def puma_arm3():
    a2, a3, d3, lc2, lc3, m2, m3, I1, Ix2, Iy2, Iz2, Ix3, Iy3, Iz3, g = P(
        "a2", "a3", "d3", "lc2", "lc3", "m2", "m3", "I1", "Ix2", "Iy2", "Iz2", "Ix3", "Iy3",
        "Iz3", "g")
    z1 = column(s1, -c1, 0)
    x2, y2 = column(c1 * c2, s1 * c2, s2), column(-c1 * s2, -s1 * s2, c2)
    x3, z3 = column(c1 * c23, s1 * c23, s23), column(-c1 * s23, -s1 * s23, c23)
    bodies = [
        (1, ZERO, axes(column(c1, s1, 0), Z0, z1), diag(y=I1), [Z0, ZERO, ZERO]),
        (m2, lc2 * x2, axes(x2, y2, z1), diag(Ix2, Iy2, Iz2), [Z0, z1, ZERO]),
        (m3, a2 * x2 + d3 * z1 + a3 * x3 + lc3 * z3, axes(x3, -z1, z3), diag(Ix3, Iy3, Iz3),
         [Z0, z1, z1]),
    ]
    return bodies, g, None, None


ARMS = {"elbow_rrr": elbow, "scara_rrp": scara, "stanford_rrp": stanford,
        "cylindrical_rpp": cylindrical, "puma560_arm3": puma_arm3}


@functools.cache
def reference(name):
    bodies, g, closed_M, closed_g = ARMS[name]()
    M, C, gv = lagrange(bodies, g)
    return M, C, gv, closed_M, closed_g


@functools.cache
def dynamics(name):
    return eomgen.derive(eomgen.load(example_path(name)))


def random_values(symbols, rng):
    return {s: float(rng.uniform(0.5, 2.0)) for s in symbols}


def evaluate(matrix, values):
    return np.array(matrix.xreplace({k: sp.Float(v) for k, v in values.items()}).evalf(),
                    dtype=float)


def states(dyn, rng, count=3):
    for _ in range(count):
        values = random_values([p.symbol for p in dyn.parameters], rng)
        q = rng.uniform(-np.pi, np.pi, 3)
        qd = rng.uniform(-2, 2, 3)
        values.update(zip(Q, q))
        values.update(zip(QD, qd))
        yield values, q, qd


@pytest.mark.parametrize("name", list(ARMS))
def test_teaching_arm_matches_the_hand_derivation(name):
    """dyn.M, dyn.C, dyn.g (the reduced textbook form) equal the Lagrangian derivation from the
    hand-written kinematics, and so do the hand-written closed forms of the YAML headers."""
    dyn = dynamics(name)
    assert dyn.simplified and dyn.q == Q
    M, C, g, closed_M, closed_g = reference(name)
    rng = np.random.default_rng(14)
    for values, _, _ in states(dyn, rng):
        M_ref, C_ref, g_ref = evaluate(M, values), evaluate(C, values), evaluate(g, values)
        scale = np.abs(M_ref).max()
        np.testing.assert_allclose(evaluate(dyn.M, values), M_ref, atol=1e-12 * scale)
        np.testing.assert_allclose(evaluate(dyn.C, values), C_ref, atol=1e-12 * scale * 4)
        np.testing.assert_allclose(evaluate(dyn.g, values), g_ref,
                                   atol=1e-12 * np.abs(g_ref).max() + 1e-12)
        if closed_M is not None:
            np.testing.assert_allclose(evaluate(closed_M, values), M_ref, atol=1e-12 * scale)
            np.testing.assert_allclose(evaluate(closed_g, values), g_ref, atol=1e-12 * scale)


@pytest.mark.parametrize("name", list(ARMS))
def test_teaching_arm_lambdify_matches_the_hand_derivation(name):
    """The NumPy functions compiled from the program (not from the expanded matrices) give the
    same M, C, g, with the parameters as keyword arguments."""
    dyn = dynamics(name)
    f = dyn.lambdify()
    M, C, g, _, _ = reference(name)
    rng = np.random.default_rng(3)
    for values, q, qd in states(dyn, rng, 2):
        kwargs = {key: values[symbol] for key, symbol in zip(f.parameters, f.symbols)}
        scale = np.abs(evaluate(M, values)).max()
        np.testing.assert_allclose(f.M(q, **kwargs), evaluate(M, values), atol=1e-12 * scale)
        np.testing.assert_allclose(f.C(q, qd, **kwargs), evaluate(C, values),
                                   atol=4e-12 * scale)
        np.testing.assert_allclose(f.g(q, **kwargs), evaluate(g, values)[:, 0],
                                   atol=1e-12 * scale)


def test_elbow_prints_in_textbook_form():
    """The elbow arm's display shows the textbook grouping: m3 (a2 c2 + lc3 c23)², angle sums,
    squares of sines and cosines, no double angles and no floats."""
    dyn = dynamics("elbow_rrr")
    tex = dyn._repr_latex_()
    assert r"m_{3} \left(a_{2} c_{2} + l_{c3} c_{23}\right)^{2}" in tex
    assert r"I_{x2} s_{2}^{2}" in tex and r"I_{y3} c_{23}^{2}" in tex
    assert r"g l_{c3} m_{3} c_{23}" in tex
    assert r"\cos" not in tex and r"\sin" not in tex and "." not in tex
    M = dyn.M
    assert not M.atoms(sp.Float) and M[0, 1] == 0
    assert not any(a.args[0].has(2 * q2) for a in M.atoms(sp.cos))  # no cos(2 q2)


def test_display_and_documents_share_the_reduced_form():
    """The Jupyter display and the LaTeX document print M and g from the same derivation
    (``dyn.textbook``), grouped the same way, with the same printer."""
    from eomgen.codegen import make_job
    from eomgen.codegen.backends.latex_backend import render_document
    from eomgen.present.display import readable_matrices

    dyn = eomgen.derive(eomgen.load(example_path("elbow_rrr")), outputs=("M", "C", "g", "tau"))
    shown = readable_matrices(dyn)
    assert shown is not None and dyn.M is dyn.textbook.M
    assert (shown["M"].applyfunc(lambda e: e.doit()) - dyn.textbook.M).applyfunc(sp.expand) \
        == sp.zeros(3, 3)
    document = render_document(make_job(dyn))
    tex = dyn._repr_latex_()
    for lhs in ("M_{1,1}", "M_{2,2}", "g_{2}"):
        line = next(line for line in document.splitlines() if line.startswith(lhs + " &= "))
        assert line[len(lhs + " &= "):] in tex


#: Forms a textbook writes that the grouping must find: a monomial times a sum, a square beside
#: other terms, a sign and a monomial pulled out (LaTeX of the display).
GROUPED_FORMS = {
    "elbow_rrr": [r"m_{3} l_{c3} \left(a_{2} c_{3} + l_{c3}\right)",
                  r"m_{3} \left(a_{2} c_{2} + l_{c3} c_{23}\right)^{2}"],
    "scara_rrp": [r"m_{2} l_{c2} \left(a_{1} c_{2} + l_{c2}\right)",
                  r"m_{3} a_{2} \left(a_{1} c_{2} + a_{2}\right)"],
    "stanford_rrp": [r"m_{3} \left(- l_{c3} + q_{3}\right)^{2} s_{2}^{2}"],
    "cylindrical_rpp": [r"g \left(m_{2} + m_{3}\right)"],
    "puma560_arm3": [r"- m_{3} d_{3} \left(a_{2} s_{2} + a_{3} s_{23} + l_{c3} c_{23}\right)",
                     r"\left(a_{2} c_{2} + a_{3} c_{23} - l_{c3} s_{23}\right)^{2}",
                     r"2 a_{2} \left(a_{3} c_{3} - l_{c3} s_{3}\right)"],
}


@pytest.mark.parametrize("name", list(ARMS))
def test_grouped_forms_are_exact_and_textbook_like(name):
    """The grouped M and g every document prints equal the derived ones exactly
    (expand(grouped − derived) = 0), and show the textbook's groupings."""
    from eomgen.present.display import readable_matrices
    from eomgen.teach import readability as rd

    dyn = dynamics(name)
    book = dyn.textbook
    shown = readable_matrices(dyn)
    for key, derived in (("M", book.M), ("g", book.g)):
        difference = shown[key].applyfunc(lambda e: e.doit()) - derived
        assert difference.applyfunc(sp.expand) == sp.zeros(*derived.shape), key
    masses = [b.mass for b in book.bodies]
    for entry in book.M:  # the term lists of the LaTeX document and the handout
        assert sp.expand(sp.Add(*rd.by_mass(entry, masses)).doit() - entry) == 0
    tex = dyn._repr_latex_()
    for form in GROUPED_FORMS[name]:
        assert form in tex, form


def test_numbers_print_as_short_decimals():
    """A model with decimal numbers: floats come out rounded to 15 digits (0.3 * 0.03 prints
    0.009, not 0.0090000000000000018) and unit factors 1.0 are gone."""
    model = eomgen.load(example_path("elbow_rrr"))
    values = {p.symbol: p.value for p in model.parameters if p.name != "g"}
    dyn = eomgen.derive(model.substitute(values))
    for matrix in (dyn.M, dyn.C, dyn.g):
        for x in matrix.atoms(sp.Float):
            assert len(repr(float(x))) <= 8, x  # e.g. 0.00225 or 0.0475
    assert not any(x == 1 for x in dyn.M.atoms(sp.Float))


def test_lambdify_equals_the_generated_numpy_module(tmp_path):
    """``dyn.lambdify()`` computes what the generated NumPy module computes."""

    from eomgen.codegen import make_job
    from eomgen.codegen.backends.numpy_backend import generate_numpy

    model = eomgen.load(example_path("puma560_arm3"))
    dyn = eomgen.derive(model, outputs=("M", "C", "g", "tau"))
    [file] = generate_numpy(make_job(dyn))
    path = tmp_path / file.name
    path.write_text(file.content)
    module = load_module(path, "generated_arm")
    f = dyn.lambdify()
    assert f.tau is not None and f.forward is not None
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.normal(size=(3, 4, 3))  # a batch of 4 states
    params = {key: 1.0 + 0.1 * k for k, key in enumerate(f.parameters)}
    for ours, theirs in ((f.M(q, **params), module.mass_matrix(q, **params)),
                         (f.C(q, qd, **params), module.coriolis_matrix(q, qd, **params)),
                         (f.g(q, **params), module.gravity_vector(q, **params)),
                         (f.tau(q, qd, qdd, **params), module.inverse_dynamics(q, qd, qdd, **params))):
        np.testing.assert_allclose(ours, theirs, rtol=1e-13, atol=1e-13)


def test_large_models_are_bounded_before_anything_is_expanded():
    """A 3-joint arm with general axes and offsets (the issue's robot whose display ran for
    20 minutes): its program is above the shared bound, so derive does not simplify, the
    display shows the summary and the notebook leaves out the textbook cells, all decided on
    the straight-line program alone."""
    from dataclasses import replace

    from support.reference import random_robot

    from eomgen.teach.notebook import build_notebook
    from eomgen.symbolic.textbook import TEXTBOOK_MAX_OPERATIONS

    model = replace(random_robot(np.random.default_rng(0), 3), name="general_arm")
    dyn = eomgen.derive(model)
    assert dyn.operation_count(["M", "C", "g"]) > TEXTBOOK_MAX_OPERATIONS
    assert not dyn.simplified
    assert "teaching-sized models" in dyn._repr_latex_()
    assert not any("textbook_derivation" in cell.source for cell in build_notebook(model).cells)
    # the teaching arms are well inside the bound, and keep the textbook form
    for name in ARMS:
        small = dynamics(name)
        assert small.simplified
        assert small.operation_count(["M", "C", "g"]) <= TEXTBOOK_MAX_OPERATIONS
