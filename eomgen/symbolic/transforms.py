"""Transforms of straight-line programs and their expressions: forward-mode time derivatives.

:func:`time_derivative` differentiates one expression along time in one pass over its tree;
:func:`time_derivative_program` extends a :class:`~eomgen.symbolic.program.Program` with the
time derivatives of some outputs, one new intermediate per intermediate, so that the program
stays linear in size (the flexible-joint flat inverse dynamics differentiate ``τ_L`` twice this
way: :mod:`eomgen.numeric.actuated`, :mod:`eomgen.symbolic.flat`).
"""

from __future__ import annotations

from typing import Mapping, Sequence

import sympy as sp

from .program import Program

__all__ = ["time_derivative", "time_derivative_program"]


def time_derivative_program(program: Program, rates: Mapping[sp.Symbol, sp.Expr],
                            names: Sequence[str], prefix: str = "d_") -> Program:
    """The program extended with the time derivatives of the outputs ``names``.

    Each intermediate ``x = f(s₁, …)`` gets ``d_x = Σ ∂f/∂s_k · ṡ_k`` (forward mode along
    time), ``rates`` giving the derivative of each input (``q → qd``, ``qd → qdd``, …; inputs
    not listed, such as parameters, are constant) and of intermediates whose derivative an
    earlier pass defined. The new outputs are named ``prefix + name``. Applying it twice gives
    second derivatives; the program stays linear in size.
    """
    d: dict[sp.Symbol, sp.Expr] = dict(rates)

    def derivative(expr: sp.Expr) -> sp.Expr:
        return time_derivative(expr, d)

    taken = {s.name for s, _ in program.assignments}
    assignments = list(program.assignments)
    for symbol, expr in program.assignments:
        if symbol in d:  # its derivative is known (from an earlier pass)
            continue
        if prefix + symbol.name in taken:
            raise ValueError(f"prefix {prefix!r} clashes with intermediate {symbol.name}")
        rate = derivative(expr)
        if rate == 0:
            continue
        if rate.is_Atom:
            d[symbol] = rate
            continue
        new = sp.Symbol(prefix + symbol.name, real=True)
        assignments.append((new, rate))
        d[symbol] = new
    outputs = list(program.outputs)
    for name in names:
        outputs.append((prefix + name, program.output(name).applyfunc(derivative)))
    return Program(tuple(assignments), tuple(outputs))


def time_derivative(expr: sp.Expr, d: Mapping[sp.Symbol, sp.Expr], memo: dict | None = None
                    ) -> sp.Expr:
    """``d/dt expr`` by one pass over the expression tree (product and chain rules), symbols
    changing at the rates ``d`` (the others constant): linear in the size of ``expr``, where
    ``sp.diff`` by each symbol in turn would be quadratic. ``memo`` caches the derivatives of
    subexpressions (a fresh one when None).

    >>> q, qd = sp.symbols("q qd")
    >>> time_derivative(q ** 2 * sp.sin(q), {q: qd})
    q**2*qd*cos(q) + 2*q*qd*sin(q)
    """
    if memo is None:
        memo = {}
    if expr in memo:
        return memo[expr]
    if expr.is_Symbol:
        out = d.get(expr, sp.Integer(0))
    elif expr.is_Number or not (expr.free_symbols & d.keys()):
        out = sp.Integer(0)
    elif expr.is_Add:
        out = sp.Add(*[time_derivative(a, d, memo) for a in expr.args])
    elif expr.is_Mul:
        args = expr.args
        terms = []
        for k, a in enumerate(args):
            da = time_derivative(a, d, memo)
            if da != 0:
                terms.append(sp.Mul(*args[:k], da, *args[k + 1:]))
        out = sp.Add(*terms)
    elif expr.is_Pow and expr.exp.is_Number:
        base, e = expr.args
        out = e * base ** (e - 1) * time_derivative(base, d, memo)
    elif isinstance(expr, sp.sin):
        out = sp.cos(expr.args[0]) * time_derivative(expr.args[0], d, memo)
    elif isinstance(expr, sp.cos):
        out = -sp.sin(expr.args[0]) * time_derivative(expr.args[0], d, memo)
    else:  # anything else: by the symbols it depends on
        out = sp.Add(*[sp.diff(expr, s) * d[s] for s in expr.free_symbols if s in d])
    memo[expr] = out
    return out
