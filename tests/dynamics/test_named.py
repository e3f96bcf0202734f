"""Symbolic results beyond teaching size (issue 14): ``dyn.M`` and the others are ordinary SymPy
matrices when they are cheap to write out, else :class:`eomgen.symbolic.named.ProgramMatrix`,
the matrix in named intermediates with their definitions. Every value here is checked against
the numeric recursive Newton-Euler of :mod:`eomgen.numeric`, which shares no code with the
symbolic program."""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen import numeric
from eomgen.robots import example_path
from eomgen.symbolic import expansion, named
from eomgen.symbolic.named import ExpansionTooLargeError, ProgramMatrix
from support.reference import random_robot
from support import uniform_states


@functools.cache
def spatial5():
    """5 revolute joints with general axes and offsets, every link with mass."""
    model = random_robot(np.random.default_rng(2), 5, prismatic=False, fixed_links=False)
    return eomgen.derive(model, outputs=("M", "C", "g", "tau"))


def states(n, count=3, seed=1):
    return uniform_states(seed, n, count)


def values(dyn, q, qd=None, qdd=None):
    out = dict(zip(dyn.q, q))
    out.update(zip(dyn.qd, qd if qd is not None else np.zeros(len(q))))
    out.update(zip(dyn.qdd, qdd if qdd is not None else np.zeros(len(q))))
    return out


def close(a, b, rtol=1e-12):
    a, b = np.asarray(a, float), np.asarray(b, float)
    np.testing.assert_allclose(a.reshape(b.shape), b, rtol=0, atol=rtol * max(1.0, np.abs(b).max()))


@pytest.mark.slow
def test_large_model_gives_the_named_form_after_bounded_work(monkeypatch):
    """The 5-joint arm's M is not written out: derive's result tries the expansion within
    AUTO_EXPAND_WORK term operations, stops, and gives the named form."""
    spent = []
    spend = expansion.Polynomials.spend

    def counting(self, work, size, what):
        spent.append(self.work + work)
        return spend(self, work, size, what)

    monkeypatch.setattr(expansion.Polynomials, "spend", counting)
    dyn = eomgen.derive(spatial5().model, outputs=("M",))
    M = dyn.M
    assert isinstance(M, ProgramMatrix) and M.shape == (5, 5) and M.rows == M.cols == 5
    assert max(spent) <= named.AUTO_EXPAND_WORK + 5000 ** 2  # the limit plus one product
    assert M.free_symbols <= set(dyn.q)  # inputs only, no intermediates
    assert {s for s, _ in M.subexpressions} <= {s for s, _ in dyn.program.assignments}


@pytest.mark.slow
def test_named_form_evaluates_to_the_numeric_model():
    """Indexing, substitution, evalf, products with SymPy matrices and lambdify all give the
    numbers of the numeric Newton-Euler; substituting every input gives an ordinary Matrix."""
    dyn = spatial5()
    nm = numeric.numeric_model(dyn.model)
    M, C, g, tau = dyn.M, dyn.C, dyn.g, dyn.tau
    assert all(isinstance(x, ProgramMatrix) for x in (M, C, tau))
    f = M.lambdify([dyn.q])
    for q, qd, qdd in states(5):
        at = values(dyn, q, qd, qdd)
        M_ref = numeric.M_rnea(nm, q)
        numbers = M.subs(at)
        assert isinstance(numbers, sp.MatrixBase) and not numbers.free_symbols
        close(numbers, M_ref)
        close(f(q), M_ref)
        close(M[1, 3].evalf(subs=at), M_ref[1, 3])
        close(M[1:3, :].xreplace(at), M_ref[1:3, :])
        tau_ref = numeric.rnea(nm, q, qd, qdd)
        close(tau.subs(at), tau_ref)
        # formed with matrix arithmetic from M, C, g (the named forms of one program)
        formed = M * sp.Matrix(dyn.qdd) + C * sp.Matrix(dyn.qd) + g
        close(formed.xreplace(at), tau_ref)
        close(dyn.K.xreplace(at), numeric.kinetic_energy(nm, q, qd))
    partial = M.subs(dyn.q[0], 0.3)  # a partial substitution folds what became numbers
    assert isinstance(partial, ProgramMatrix)
    assert len(partial.subexpressions) < len(M.subexpressions)
    assert dyn.q[0] not in partial.free_symbols
    with pytest.raises(ValueError, match="evalf needs values for q1"):
        M.evalf(subs={x: 0 for x in dyn.q[1:]})
    with pytest.raises(AttributeError, match=r"call \.expand\(\)"):
        M.jacobian(dyn.q)


def test_expand_stops_with_a_clear_message():
    dyn = spatial5()
    with pytest.raises(ExpansionTooLargeError, match=r"M: .*passed 1000 terms.*max_terms=None"):
        dyn.M.expand(max_terms=1000)


def test_named_form_displays_with_its_subexpressions():
    tex = spatial5().M._repr_latex_()
    assert tex.startswith("$$") and r"\text{where}" in tex and "more (.subexpressions)" in tex
    assert "ProgramMatrix(M, 5×5" in repr(spatial5().M)


def test_expanded_g_is_the_numeric_gravity():
    """Written out (``expand``), g of the 5-joint arm is an ordinary polynomial in the sines
    and cosines with no sin² left, equal to the numeric g."""
    dyn = spatial5()
    g = dyn.named("g").expand()
    assert isinstance(g, sp.MatrixBase) and g.free_symbols <= set(dyn.q)
    assert not any(p.exp >= 2 for p in g.atoms(sp.Pow) if isinstance(p.base, sp.sin))
    f = sp.lambdify([dyn.q], g)
    nm = numeric.numeric_model(dyn.model)
    for q, _, _ in states(5):
        close(f(q), numeric.gravity_torques(nm, q))


@pytest.mark.slow
def test_expanded_M_of_the_spatial_arm_is_the_numeric_M():
    dyn = spatial5()
    M = dyn.M.expand(max_terms=None)  # about 2,800 terms; a few seconds
    assert isinstance(M, sp.MatrixBase) and M.free_symbols <= set(dyn.q)
    f = sp.lambdify([dyn.q], M)
    nm = numeric.numeric_model(dyn.model)
    for q, _, _ in states(5):
        close(f(q), numeric.M_rnea(nm, q))


def test_a_six_joint_arm_that_expands_cheaply_is_an_ordinary_matrix():
    """The PUMA 560's M (exact DH twists, many zeros) writes out to a few hundred terms: an
    ordinary SymPy Matrix, equal to the numeric M."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the published inertias are not physical (see file)
        model = eomgen.load(example_path("puma560_dh"))
    dyn = eomgen.derive(model, outputs=("M",))
    assert isinstance(dyn.M, sp.MatrixBase)
    f = sp.lambdify([dyn.q], dyn.M)
    nm = numeric.numeric_model(model)
    for q, _, _ in states(6):
        close(f(q), numeric.M_rnea(nm, q))


def test_teaching_sized_models_keep_the_textbook_matrix():
    """The planar arm: dyn.M is the reduced textbook Matrix; unsimplified it is the written-out
    program, an ordinary Matrix equal to it."""
    model = eomgen.load(example_path("planar_2link"))
    dyn = eomgen.derive(model)
    assert dyn.M is dyn.textbook.M
    raw = eomgen.derive(model, simplify=False)
    assert isinstance(raw.M, sp.MatrixBase) and isinstance(raw.C, sp.MatrixBase)
    difference = (raw.M - dyn.M).applyfunc(lambda e: sp.expand(sp.expand_trig(e)))
    difference = difference.subs(sp.sin(dyn.q[1]) ** 2, 1 - sp.cos(dyn.q[1]) ** 2)
    assert difference.applyfunc(sp.expand) == sp.zeros(2, 2)


def test_expand_program_keeps_exact_numbers_and_parameters():
    """Exact rationals and symbolic parameters stay exact: the expansion of a small program
    equals SymPy's own expansion once sin² is written 1 − cos²."""
    x0, x1, q1, q2, a = sp.symbols("x0 x1 q1 q2 a", real=True)
    program = [(x0, sp.cos(q1) * a + sp.Rational(1, 3) * sp.sin(q2)),
               (x1, x0 ** 2 - sp.sin(q1) * x0)]
    [out] = expansion.expand_program(program, [x1 * sp.cos(q2) + 2])
    direct = sp.expand(((sp.cos(q1) * a + sp.sin(q2) / 3) ** 2
                        - sp.sin(q1) * (sp.cos(q1) * a + sp.sin(q2) / 3)) * sp.cos(q2) + 2)
    direct = sp.expand(direct.subs({sp.sin(q1) ** 2: 1 - sp.cos(q1) ** 2,
                                    sp.sin(q2) ** 2: 1 - sp.cos(q2) ** 2}))
    assert out == direct and not out.atoms(sp.Float)  # the same canonical SymPy expression
    assert out.args == direct.args


@pytest.mark.parametrize("which", ["planar_2link", pytest.param("spatial5",
                                                                 marks=pytest.mark.slow)])
def test_dynamics_pickle_after_sympy_lambdify_and_evaluation(which):
    """``sympy.lambdify`` of M, then a call: a named entry compiles its program on first use
    (a function of lambdify's own namespace, which pickle cannot name), yet the Dynamics
    still pickles, and the copy's M is the original's, evaluating to the same numbers."""
    import pickle

    dyn = (eomgen.derive(eomgen.load(eomgen.example_path("planar_2link")))
           if which == "planar_2link" else spatial5())
    inputs = list(dyn.q) + sorted(dyn.M.free_symbols - set(dyn.q), key=str)
    point = [0.1 * (k + 1) for k in range(len(inputs))]
    before = np.asarray(sp.lambdify(inputs, dyn.M)(*point), float)
    copy = pickle.loads(pickle.dumps(dyn))
    assert sp.Matrix(copy.M) == sp.Matrix(dyn.M)  # entry by entry (named: the same programs)
    close(np.asarray(sp.lambdify(inputs, copy.M)(*point), float), before)
