"""The operation count of an expression (eomgen.symbolic.program.count_ops), which every
module's docstrings and the routes' choice report: SymPy's own ``count_ops``, number for
number, counted without SymPy's new expressions."""

from __future__ import annotations

import sympy as sp

import eomgen
from eomgen.codegen.generate import derived_outputs
from eomgen.dynamics import derive
from eomgen.symbolic.program import count_ops
from support import ROOT
from support.expressions import random_expressions


def test_count_is_sympys_on_random_expressions():
    for expr in random_expressions(1500, seed=5):
        assert count_ops(expr) == sp.count_ops(expr), expr


def test_count_is_sympys_on_a_derived_program_with_divisions():
    """The planar arm, its parameters symbols (as ``load`` gives them): M⁻¹, the ABA and the
    derivatives divide; every assignment and output entry counts as SymPy counts it."""
    model = eomgen.load(ROOT / "eomgen" / "robots" / "planar_2link.yaml")
    assert model.parameters and all(p.symbol.is_Symbol for p in model.parameters)
    outputs = derived_outputs(["forward_dynamics_aba", "linearize", "regressor"])
    program = derive(model, outputs=outputs, simplify=False).program
    exprs = [e for _, e in program.assignments] + [e for _, m in program.outputs for e in m]
    assert any(f.is_Pow and f.exp < 0 for e in exprs for f in sp.preorder_traversal(e)
               if isinstance(f, sp.Expr))  # the divisions are there
    for expr in exprs:
        assert count_ops(expr) == sp.count_ops(expr), expr
    assert program.operation_count() == sum(sp.count_ops(e) for e in exprs)
