"""Second derivatives of the inverse dynamics as straight-line programs (issue 42).

The first derivatives of :mod:`eomgen.symbolic.derivatives` are the Newton–Euler program
differentiated once in forward mode; their program (the derivatives ``dx_d`` of each
intermediate ``x`` along each direction ``d``, and the partials they multiply) is itself a
straight-line program in the derivation's builder. :func:`second_order` differentiates it once
more in forward mode, along a second set of directions ``e``: an intermediate of the first pass
gets, per direction, ``Σ ∂f/∂a · da_e`` over its arguments, where ``da_e`` of a quantity of the
dynamics is its first derivative, already named by the first pass, and that of a first
derivative or a partial is named here. Only the pairs ``(d, e)`` asked for are carried: a
backward sweep from the outputs says, per intermediate, along which ``e`` its derivative is
needed, so that the symmetric pairs (``∂²/∂q_j∂q_k`` with ``k < j``) cost nothing and are
mirrored at the end.

Outputs (symbols of :mod:`eomgen.outputs`), n = NV, ``JOINT_NAMES`` order, in Pinocchio's layout
of ``ComputeRNEASecondOrderDerivatives`` (``algorithm/rnea-second-order-derivatives.hpp``), each
3-index tensor ``T[i, j, k]`` returned as the n × n² matrix with entry ``[i, j·n + k]``
(``reshape(n, n, n)`` in C order gives ``T``):

* ``d2tau_dqdq[i, j, k] = ∂²τ_i/∂q_j∂q_k`` (symmetric in j, k);
* ``d2tau_dvdv[i, j, k] = ∂²τ_i/∂q̇_j∂q̇_k`` (symmetric in j, k);
* ``dtau_dqdv[i, j, k] = ∂²τ_i/∂q_j∂q̇_k``: ∂(∂τ/∂q)/∂q̇, as Pinocchio's ``data.d2tau_dqdv(i, j,
  k)`` holds it (checked against it: q along the second index, q̇ along the third);
* ``dtau_dadq[i, j, k] = ∂²τ_i/∂q̈_j∂q_k = ∂M_ij/∂q_k``;
* ``d2tau``: the four side by side (one program, one call).

Models whose configuration has more entries than their velocity (quaternion joints: nq > nv)
are refused (the catalogue marks these outputs as not derived on the chart), and so are
coupled joints (:data:`eomgen.symbolic.couplings.PROJECTIONS` does not list them).
"""

from __future__ import annotations

import sympy as sp

from .builders import builds
from .derivatives import differentiate, forward_mode_map
from .program import ProgramBuilder
from .tangent import tangent_seeds

#: the key of this module's work in ``Derivation.shared``
_SHARED = __name__

#: Per output symbol: the inputs of the second and the third index of ``T[i, j, k]``.
TENSORS: dict[str, tuple[str, str]] = {
    "d2tau_dqdq": ("q", "q"), "d2tau_dvdv": ("qd", "qd"), "dtau_dqdv": ("q", "qd"),
    "dtau_dadq": ("qdd", "q")}


def second_order(b: ProgramBuilder, outputs, seeds: dict, pairs) -> list[dict]:
    """Second derivatives of the expressions ``outputs`` along the direction pairs ``pairs``,
    defined in ``b`` by forward mode over their first-derivative program.

    Parameters
    ----------
    b:
        The builder the outputs' intermediates were defined in.
    outputs:
        Expressions to differentiate twice.
    seeds:
        ``{input symbol: direction}`` as for :func:`eomgen.symbolic.derivatives.forward_mode`
        (every direction of ``pairs`` among them); the seeds' own derivatives must be constants.
    pairs:
        ``(d, e)`` pairs of directions: the derivative along ``d``, then along ``e``.

    Returns
    -------
    list of dict
        Per output, ``{(d, e): ∂²/∂e∂d}`` for the pairs asked for, structural zeros left out.

    Examples
    --------
    >>> x, y = sp.symbols("x y", real=True)
    >>> b = ProgramBuilder({"x", "y"})
    >>> s = b.define(sp.sin(x) * y, "s")
    >>> [d2] = second_order(b, [s * s], {x: ("x", 0), y: ("y", 0)},
    ...                     [(("x", 0), ("y", 0)), (("y", 0), ("y", 0))])
    >>> values = {}
    >>> for symbol, expr in b.assignments:
    ...     values[symbol] = expr.subs(values)
    >>> by = {"x": x, "y": y}
    >>> [sp.simplify(d2[a, c].subs(values) - sp.diff((sp.sin(x) * y)**2, by[a[0]], by[c[0]]))
    ...  for a, c in sorted(d2)]
    [0, 0]
    """
    rows, D1 = forward_mode_map(b, outputs, seeds)
    wanted: dict = {}
    for d, e in pairs:
        wanted.setdefault(d, set()).add(e)
    # backward: along which second directions each intermediate's derivative is needed
    need: dict = {}

    def ask(expr, directions) -> None:
        for a in expr.free_symbols:
            if a not in D1:
                need.setdefault(a, set()).update(directions)

    for row in rows:
        for d, first in row.items():
            if d in wanted:
                ask(first, wanted[d])
    assignments = list(b.assignments)
    for symbol, expr in reversed(assignments):
        if symbol in need:
            ask(expr, need[symbol])
    # forward: the derivatives, the first pass's reused where it named them
    D2: dict = {}
    partials: dict = {}

    def along(free, directions) -> dict:
        out = {}
        for a in free:
            known = D1[a] if a in D1 else D2.get(a)
            if known:
                chosen = {e: v for e, v in known.items() if e in directions}
                if chosen:
                    out[a] = chosen
        return out

    for assignment in assignments:
        symbol, expr = assignment
        if symbol not in need:
            continue
        free = getattr(assignment, "free", None) or expr.free_symbols
        derivative = differentiate(b, expr, free, along(free, need[symbol]), symbol.name,
                                   True, partials)
        if derivative:
            D2[symbol] = derivative
    result = []
    for i, row in enumerate(rows):
        out = {}
        for d, first in row.items():
            if d not in wanted:
                continue
            hint = f"2tau{i + 1}_{d[0]}{d[1] + 1}"
            for e, value in differentiate(b, first, first.free_symbols,
                                          along(first.free_symbols, wanted[d]), hint, True,
                                          partials).items():
                out[(d, e)] = value
        result.append(out)
    return result


def _key(symbol: str, j: int, k: int) -> tuple:
    """The direction pair ``(d, e)`` whose second derivative is ``T[i, j, k]`` of output
    ``symbol``: the upper triangle ``k ≥ j`` of the symmetric ones. (For ``dtau_dqdv``,
    differentiating along q first costs about as much as along q̇ first: 5,005 operations for
    the four tensors of the UR5 against 5,048.)"""
    first, second = TENSORS[symbol]
    if first == second and k < j:
        j, k = k, j
    return (first, j), (second, k)


def inverse_dynamics_second_derivatives(derivation, symbols) -> dict:
    """``{symbol: n × n² matrix}`` of the :data:`TENSORS` ``symbols`` of the derivation's τ
    (one second-order pass for all of them)."""
    work = derivation.shared.setdefault(_SHARED, {})
    missing = sorted(set(symbols) - set(work))
    if missing:
        n = len(derivation.inputs["qd"])
        inputs = {first for s in missing for first in TENSORS[s]}
        seeds = dict(tangent_seeds(derivation))
        for name in ("qd", "qdd"):
            if name in inputs:
                seeds.update({s: (name, k) for k, s in enumerate(derivation.inputs[name])})
        pairs = sorted({_key(s, j, k) for s in missing for j in range(n) for k in range(n)})
        b = derivation.builder
        rows = second_order(b, list(derivation.output("tau")), seeds, pairs)
        zero = sp.Integer(0)
        for s in missing:
            T = sp.zeros(n, n * n)
            for i, row in enumerate(rows):
                for j in range(n):
                    for k in range(n):
                        T[i, j * n + k] = row.get(_key(s, j, k), zero)
            work[s] = T
    return {s: work[s] for s in symbols}


@builds(*TENSORS, "d2tau")
def build_second_derivatives(derivation, wanted) -> dict:
    """The builder of the second-derivative outputs (see the module's docstring)."""
    tensors = set(TENSORS) if "d2tau" in wanted else set(wanted) & set(TENSORS)
    found = inverse_dynamics_second_derivatives(derivation, sorted(tensors))
    result = {s: found[s] for s in wanted if s in TENSORS}
    if "d2tau" in wanted:
        result["d2tau"] = sp.Matrix.hstack(*(found[s] for s in TENSORS))
    return result


__all__ = ["TENSORS", "build_second_derivatives", "inverse_dynamics_second_derivatives",
           "second_order"]
