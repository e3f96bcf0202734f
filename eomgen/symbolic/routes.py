"""Route choice: which exact program builds M, C and g for a given robot.

Each of M, C and g has two exact programs (*routes*), built by the algorithm modules below this
one; :func:`derive_program` (what :func:`eomgen.derive` uses, through :func:`build_lagrangian`)
builds every route of each asked output into a scratch builder and keeps, per output, the one
with fewer operations for this robot (:func:`cheapest_routes`):

* ``M``: the body-frame CRBA (:func:`eomgen.symbolic.crba.M_program`) or ``M_ij = S_iᵀ I^c_j
  S_j`` in world axes (:func:`eomgen.symbolic.composite.composite_M_program`);
* ``C``: Echeandia and Wensing's O(n²) recursion
  (:func:`eomgen.symbolic.composite.coriolis_program`) or the Christoffel symbols of the
  closed-form ∂M/∂q (:func:`eomgen.symbolic.composite.christoffel_coriolis_program`);
* ``g``: the Newton–Euler program at rest (:func:`eomgen.symbolic.newton_euler.
  inverse_dynamics_program`) or ``g_i = −g_vecᵀ f_i`` from the world-frame composite bodies
  (:func:`eomgen.symbolic.composite.composite_gravity_program`).

Every route gives the same matrices (C is always the Christoffel C); only the operation count
of the program differs. Units: SI (rad, m, kg, s). Sign convention: M q̈ + C q̇ + g = τ.
"""

from __future__ import annotations

from typing import Iterable

import sympy as sp

from ..model.bodies import BodyTree
from ..model import Vec3
from .builders import builds
from .composite import (christoffel_coriolis_program, composite_gravity_program,
                        composite_M_program, coriolis_program, forward_kinematics,
                        potential_energy)
from .crba import M_program
from .charts import corrected_coriolis
from .newton_euler import inverse_dynamics_program
from .program import Program, ProgramBuilder, rough_operation_count

#: Above this many joints the Christoffel-symbol C is not tried: its O(n³) program was larger
#: than the recursion's O(n²) one on every robot measured with 6 joints (random arms with
#: general axes: 4,222–5,007 against 3,701–4,140 operations; the 6-link spatial chain of
#: benchmarks/complexity.py 4,059 against 3,354; 5 joints: 3,163–3,512 against 3,120–3,351),
#: and building it dominates ``derive``'s time for long chains.
CHRISTOFFEL_MAX_JOINTS = 5


def _rnea_gravity(tree, q, qd, gravity, b):
    zero = (sp.Integer(0),) * len(tree.bodies)
    return inverse_dynamics_program(tree, q, zero, zero, gravity, b, hint="g")


def _christoffel_route(tree, q, qd, gravity, b):
    if len(tree.bodies) > CHRISTOFFEL_MAX_JOINTS:
        return None
    return christoffel_coriolis_program(tree, q, qd, b)


def routes() -> dict:
    """The programs of each output: ``{output: ((name, build), …)}``, in the order they are
    tried (the first wins a tie), with ``build(tree, q, qd, gravity, b)`` building the output's
    matrix into the builder ``b`` and returning it, or None when the route is not tried for
    this robot (the Christoffel C above :data:`CHRISTOFFEL_MAX_JOINTS` joints)."""
    return {
        "M": (("CRBA", lambda tree, q, qd, gravity, b: M_program(tree, q, b)),
              ("composite", lambda tree, q, qd, gravity, b: composite_M_program(tree, q, b))),
        "C": (("recursion", lambda tree, q, qd, gravity, b: coriolis_program(tree, q, qd, b)),
              ("Christoffel", _christoffel_route)),
        "g": (("Newton-Euler", _rnea_gravity),
              ("composite", lambda tree, q, qd, gravity, b:
               composite_gravity_program(tree, q, gravity, b))),
    }


def cheapest_routes(tree: BodyTree, q, qd, gravity: Vec3, outputs: Iterable[str],
                    reserved=(), christoffel: bool = True) -> tuple[dict[str, str], Program]:
    """Build every route (see :func:`routes`) of each of ``outputs`` into one scratch
    builder, where they share their common work (the world-frame composites, sines and
    cosines), and keep for each output the route whose own program has the fewest operations
    (:func:`~eomgen.symbolic.program.rough_operation_count`; the first route on a tie).

    Returns ``({output: route name}, the program of the chosen outputs, pruned)``.
    """
    # A builder of its own, not a derivation's: it holds the losing routes too, and only the
    # chosen outputs' pruned program leaves it (the caller absorbs it into its derivation).
    scratch = ProgramBuilder(reserved)
    table = routes()
    chosen, best_matrices = {}, []
    for output in outputs:
        best = None
        for name, build in table[output]:
            if name == "Christoffel" and not christoffel:
                continue
            matrix = build(tree, q, qd, gravity, scratch)
            if matrix is None:  # route not tried for this robot
                continue
            used = Program(tuple(scratch.assignments), ((output, matrix),)).pruned([output])
            count = rough_operation_count([e for _, e in used.assignments] + list(matrix))
            if best is None or count < best[0]:
                best = (count, name, matrix)
        chosen[output] = best[1]
        best_matrices.append((output, best[2]))
    program = Program(tuple(scratch.assignments), tuple(best_matrices))
    return chosen, program.pruned([o for o, _ in best_matrices])


def derive_program(tree: BodyTree, q, qd, gravity: Vec3, outputs: set[str], b: ProgramBuilder,
                   christoffel: bool = True) -> dict:
    """Build M, C and/or g (as asked in ``outputs``) into the program builder ``b``, each by
    the cheaper of its two exact programs for this robot (module docstring,
    :func:`cheapest_routes`): the body-frame CRBA is cheapest for joint axes along the link
    frames' axes (the Panda: 641 operations against 1,784), the world-frame composites for
    general axes, whose body-frame rotations cost more than one world rotation per body; the
    Christoffel C has fewer intermediates for two to four joints and is tried up to
    :data:`CHRISTOFFEL_MAX_JOINTS` joints. With g comes ``P``, the potential energy, from the
    world-frame kinematics (:func:`eomgen.symbolic.composite.potential_energy`).

    ``christoffel=False`` leaves the Christoffel C out (a free flyer's chart coordinates are
    held at zero: nothing to differentiate by).

    Returns a dict with SymPy matrices in terms of intermediates: ``"M"`` (n×n), ``"C"`` (n×n),
    ``"g"`` (n×1), plus ``"P"`` (1×1 potential energy [J], when g is asked).
    """
    _, program = cheapest_routes(tree, q, qd, gravity,
                                 [o for o in ("M", "g", "C") if o in outputs], b.reserved,
                                 christoffel=christoffel)
    result = b.absorb(program)
    if "g" in outputs:
        kin = forward_kinematics(tree, q, b)
        result["P"] = sp.Matrix([[b.define(potential_energy(tree, kin, gravity), "P", ("P",))]])
    return result


@builds("M", "C", "g")
def build_lagrangian(derivation, wanted) -> dict:
    """The builder of M, C and g in :mod:`eomgen.outputs`: :func:`derive_program` on the
    derivation's body tree for the ``wanted`` ones, with the potential energy ``P`` [J] when g is
    among them."""
    wanted = set(wanted)
    chart = derivation.model.nq > derivation.model.dof
    if chart and "C" in wanted:
        wanted.add("M")  # with a chart, C is the chart's corrected with M
    result = derive_program(derivation.tree, derivation.q, derivation.qd,
                            derivation.model.gravity, wanted, derivation.builder,
                            christoffel=not chart)
    if chart and "C" in result:
        b = derivation.builder
        C = corrected_coriolis(derivation, result["C"], result["M"], derivation.qd)
        result["C"] = C.applyfunc(lambda e: e if e.is_Atom else b.define(e, "Cff", ("C",)))
    return {name: result[name] for name in ("M", "C", "g", "P") if name in result}


__all__ = ["CHRISTOFFEL_MAX_JOINTS", "build_lagrangian", "cheapest_routes", "derive_program",
           "routes"]
