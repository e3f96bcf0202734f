"""Closed-form grouping of the standard inertial parameters (the symbolic route to base parameters).

The rules are those of Gautier & Khalil (1990, "Direct calculation of minimum set of inertial
parameters of serial robots", IEEE Trans. Robotics and Automation 6(3)) and Khalil & Dombre
("Modeling, Identification and Control of Robots", §12.5), written for an arbitrary fixed joint
placement instead of the DH/MDH link transform, in eomgen's body frames
(:mod:`eomgen.symbolic.regressor`). Working from the tips to the root, the part of body j's
parameters that its own joint cannot move relative to the parent is an equally good part of the
parent, and is pushed there:

* **revolute joint about ±e_k** (k = x, y, z of the body frame): the mass M, the first moment
  along the axis (MZ for z) and an inertia ``c (1 − e_k e_kᵀ)`` are invariant under the rotation
  and their velocity terms do not involve q̇_j. With (a, b) the two other axes in x, y, z order,
  ``c`` is the b-b moment: for z, ``c = YY`` and ``XXR = XX − YY`` remains (Khalil's rule); for
  x, ``c = ZZ`` (YYR = YY − ZZ); for y, ``c = ZZ`` (XXR = XX − ZZ).
* **helical joint about ±e_k** (a screw of pitch λ ≠ 0): the mass and the first moments move
  along the axis with the joint (their velocity terms involve λ q̇_j), so only the inertia
  ``c (1 − e_k e_kᵀ)`` is invariant (it turns about its axis and does not see a translation);
  ``c`` as for a revolute joint.
* **prismatic joint** (any axis): the body does not rotate relative to its parent, so the whole
  inertia about its origin, ``(0, 0, I)``, is pushed (the mass and first moments stay).

A pushed part ``(m, h, I)`` is moved into the parent's frame through the fixed joint placement
(:meth:`~eomgen.model.bodies.InertialParameters.transformed`): DH lengths kept as symbols stay symbols.
What a body on the fixed base pushes is unidentifiable and is dropped. The remaining special
cases (columns that vanish because of gravity or axes parallel to the first ones) are left to
the caller, who finds them numerically (:func:`eomgen.regressor.symbolic_base_parameters`).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.bodies import BodyTree, InertialParameters
from .spatial import aligned_axis

#: Slot of each Pinocchio-ordered parameter: ("m",), ("h", a), ("I", a, b).
SLOTS = (("m",), ("h", 0), ("h", 1), ("h", 2), ("I", 0, 0), ("I", 0, 1), ("I", 1, 1),
         ("I", 0, 2), ("I", 1, 2), ("I", 2, 2))


def _get(par: InertialParameters, slot) -> sp.Expr:
    if slot[0] == "m":
        return par.mass
    if slot[0] == "h":
        return par.first_moment[slot[1]]
    return par.inertia[slot[1]][slot[2]]


def _symbolic_body(symbols) -> InertialParameters:
    m, hx, hy, hz, xx, xy, yy, xz, yz, zz = symbols
    return InertialParameters(m, (hx, hy, hz), ((xx, xy, xz), (xy, yy, yz), (xz, yz, zz)))


@dataclass(frozen=True)
class Grouping:
    """Result of the grouping pass.

    Attributes
    ----------
    kept:
        Column indices (in Y's order) that survive, increasing.
    expressions:
        β of each kept column: the grouped parameter as an expression of the standard ones
        (and of the model's geometry symbols).
    eliminated:
        Column indices absorbed into other parameters (or, for bodies on the base, dropped).
    """

    kept: tuple[int, ...]
    expressions: tuple[sp.Expr, ...]
    eliminated: tuple[int, ...]


def group_parameters(tree: BodyTree, pi: tuple[sp.Symbol, ...]) -> Grouping:
    """Apply the grouping rules of the module docstring to the 10 n inertial parameters.

    Parameters
    ----------
    tree:
        The moving bodies; body ``i``'s block is columns ``10 q_index … 10 q_index + 9``.
    pi:
        Symbols of the standard parameters in Y's column order (at least the 10 n inertial).

    Raises
    ------
    ValueError
        For a revolute or helical joint whose axis is not ±x, ±y or ±z of its frame (names
        the joint).
    """
    grouped = [_symbolic_body(pi[10 * b.q_index:10 * b.q_index + 10]) for b in tree.bodies]
    eliminated: set[int] = set()
    zero = sp.Integer(0)
    for i in reversed(range(len(tree.bodies))):
        body = tree.bodies[i]
        par = grouped[i]
        col = 10 * body.q_index
        if body.joint.rotates:
            aligned = aligned_axis(body.joint.axis)
            if aligned is None:
                raise ValueError(f"joint '{body.joint.name}': the closed-form grouping needs a "
                                 f"{'helical' if body.joint.lead != 0 else 'revolute'} axis "
                                 "along ±x, ±y or ±z of the joint frame")
            k = aligned[0]
            a, b = sorted(((k + 1) % 3, (k + 2) % 3))
            c = par.inertia[b][b]
            inertia_c = tuple(tuple(c if (r == s and r != k) else zero for s in range(3))
                              for r in range(3))
            h_axis = tuple(par.first_moment[r] if r == k else zero for r in range(3))
            pushed = InertialParameters(par.mass, h_axis, inertia_c)  # type: ignore[arg-type]
            remainder = InertialParameters(
                zero, tuple(zero if r == k else par.first_moment[r] for r in range(3)),  # type: ignore
                tuple(tuple(par.inertia[r][s] - inertia_c[r][s] for s in range(3))
                      for r in range(3)))  # type: ignore[arg-type]
            eliminated |= {col, col + 1 + k, col + SLOTS.index(("I", b, b))}
            if body.joint.lead != 0:  # helical: the mass and first moments stay (docstring)
                pushed = InertialParameters(zero, (zero,) * 3, inertia_c)  # type: ignore
                remainder = InertialParameters(par.mass, par.first_moment, remainder.inertia)
                eliminated -= {col, col + 1 + k}
        else:
            pushed = InertialParameters(zero, (zero,) * 3, par.inertia)  # type: ignore[arg-type]
            remainder = InertialParameters(par.mass, par.first_moment)
            eliminated |= {col + e for e in range(4, 10)}
        grouped[i] = remainder
        if body.parent >= 0:
            grouped[body.parent] = grouped[body.parent] + pushed.transformed(body.placement)
    kept, expressions = [], []
    for i, body in sorted(enumerate(tree.bodies), key=lambda ib: ib[1].q_index):
        col = 10 * body.q_index
        for e, slot in enumerate(SLOTS):
            if col + e not in eliminated:
                kept.append(col + e)
                expressions.append(sp.expand(_get(grouped[i], slot)))
    return Grouping(tuple(kept), tuple(expressions), tuple(sorted(eliminated)))
