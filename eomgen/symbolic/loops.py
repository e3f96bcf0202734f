"""Loop closures, symbolically: the constraint ``Φ(q)``, its Jacobian ``J_l`` and ``J̇_l q̇``.

A :class:`~eomgen.model.Loop` holds frame B (a link and a pose in it) on frame A. From the
frame kinematics of :mod:`eomgen.symbolic.frames` (world-aligned, at the link origins) shifted
to the two frames, with ``p`` their origins, ``R`` their axes, ``ω`` their angular velocities
and ``a``, ``α`` their accelerations at ``q̈ = 0``, all in **world** axes:

* translational rows, ``e ∈ {x, y, z}`` (world axes) or, for a planar loop, the two in-plane
  axes ``u, v`` of :func:`plane_axes`: ``Φ = eᵀ (p_B − p_A)``, ``J = eᵀ (J_B,lin − J_A,lin)``,
  ``J̇ q̇ = eᵀ (a_B − a_A)``, so that ``Φ̇ = J q̇`` exactly;
* rotational rows of a weld, ``e ∈ {x, y, z}`` (or the plane normal ``n``): ``J q̇ = eᵀ (ω_B −
  ω_A)``, ``J̇ q̇ = eᵀ (α_B − α_A)``, ``Φ = eᵀ ½ Σ_k r_A,k × r_B,k`` (r the columns of R: the
  rotation vector's sine, ``sin θ u``);
* rotational rows of a hinge of axis ``k`` (frame a's axes): ``u_i = R_A t_i`` with ``t_1,
  t_2`` :func:`plane_axes` of ``k``; ``J q̇ = u_iᵀ (ω_B − ω_A)``, ``J̇ q̇ = u_iᵀ (α_B − α_A) +
  (ω_A × u_i)ᵀ (ω_B − ω_A)``, ``Φ = u_iᵀ (R_A k × R_B k)``.

Rotational ``Φ`` rows vanish where the loop is closed, and their derivative is ``J q̇`` there
(their ``J`` is the velocity constraint, not ``∂Φ/∂q`` away from closure). The loop force
``λ`` (the rows' multipliers) acts on B's body at B's origin, ``−λ`` on A's, in the rows' axes:
``M q̈ + C q̇ + g = τ + J_lᵀ λ``.

The constrained outputs (:func:`build_constraints`) stack the scene's contact rows first
(:func:`eomgen.symbolic.frames.build_contacts`), then its loops' rows: ``J_c``, ``J̇_c q̇`` and
the forces ``F_c`` of ``constrained_forward_dynamics`` cover contacts and loops together
(``CONTACT_ROWS`` names every row).
"""

from __future__ import annotations

import sympy as sp

from ..errors import GenerationError
from ..model import HINGE, WELD, RobotModel, Transform
from ..model.loop import in_plane_axes
from .builders import builds, provides, sizes
from .frames import build_contacts, contact_rows, frame_kinematics
from .spatial import cross, matmul, matvec

#: Outputs of :func:`build_constraints`: the loop rows, and the contact-and-loop rows.
LOOP_SYMBOLS = ("Phi_l", "J_l", "dJqd_l")


def _exact(x) -> sp.Expr:
    value = float(x)
    return sp.Integer(int(value)) if value.is_integer() else sp.Float(value)


def plane_axes(normal) -> tuple[tuple, tuple]:
    """:func:`eomgen.model.loop.in_plane_axes` of ``normal`` as SymPy numbers, exact for axes.

    >>> plane_axes((0, 0, 1))
    ((1, 0, 0), (0, 1, 0))
    """
    return tuple(tuple(_exact(x) for x in t) for t in in_plane_axes(normal))


def loop_rows(model: RobotModel) -> tuple[str, ...]:
    """``LOOP_ROWS``: the rows of ``Φ_l``, ``J_l`` and the loop forces, ``<loop>.<axis>``."""
    return tuple(r for loop in model.loops for r in loop.rows)


def constraint_rows(model: RobotModel) -> tuple[str, ...]:
    """``CONTACT_ROWS`` of a model with loops: the contact rows, then the loop rows."""
    return contact_rows(model) + loop_rows(model)


@sizes("F_c")
def constraint_row_count(model: RobotModel) -> int:
    """The length of ``F_c``: contact rows and loop rows."""
    return len(constraint_rows(model))


@provides("LOOP_NAMES", "LOOP_ROWS")
def loop_constants(dynamics) -> dict[str, tuple[str, ...]]:
    """``LOOP_NAMES`` and ``LOOP_ROWS`` (:func:`loop_rows`)."""
    model = dynamics.model
    return {"LOOP_NAMES": tuple(loop.name for loop in model.loops),
            "LOOP_ROWS": loop_rows(model)}


@provides("ACTUATED_JOINTS", "LOOP_ROWS")
def parallel_constants(dynamics) -> dict[str, tuple[str, ...]]:
    """``ACTUATED_JOINTS`` (the scene's ``actuated:``, else every joint) and ``LOOP_ROWS``."""
    model = dynamics.model
    return {"ACTUATED_JOINTS": tuple(model.actuated or model.joint_names),
            "LOOP_ROWS": loop_rows(model)}


@provides("CONTACT_NAMES", "CONTACT_ROWS")
def constraint_constants(dynamics) -> dict[str, tuple[str, ...]]:
    """``CONTACT_NAMES`` and ``CONTACT_ROWS`` (:func:`constraint_rows`): contacts, then
    loops."""
    model = dynamics.model
    return {"CONTACT_NAMES": tuple(c.name for c in model.contacts)
            + tuple(loop.name for loop in model.loops),
            "CONTACT_ROWS": constraint_rows(model)}


def _shifted(values: dict, pose: Transform, qd, b, hint: str) -> dict:
    """A link's frame kinematics (``p``, ``R``, world-aligned ``J``, ``dJqd``) moved to the
    frame at ``pose`` in the link, with its angular velocity ``w`` and acceleration ``al``."""
    n = len(qd)
    J, bias = values["J"], values["dJqd"]
    w = b.define_all(tuple(sp.Add(*[J[3 + r, c] * qd[c] for c in range(n)]) for r in range(3)),
                     f"{hint}w")
    al = tuple(bias[3 + r] for r in range(3))
    R_link = tuple(tuple(values["R"][r, c] for c in range(3)) for r in range(3))
    if all(x == 0 for x in pose.translation):
        p = tuple(values["p"])
        Jlin = J[:3, :]
        a = tuple(bias[r] for r in range(3))
    else:
        r_ = b.define_all(matvec(R_link, pose.translation), f"{hint}r")
        p = b.define_all(tuple(values["p"][i] + r_[i] for i in range(3)), f"{hint}p")
        Jlin = sp.zeros(3, n)
        for c in range(n):
            col = cross(tuple(J[3 + i, c] for i in range(3)), r_)
            for i in range(3):
                Jlin[i, c] = b.define(J[i, c] + col[i], f"{hint}J{i}_{c + 1}")
        wxr = cross(w, r_)
        extra = [x + y for x, y in zip(cross(al, r_), cross(w, wxr))]
        a = b.define_all(tuple(bias[i] + extra[i] for i in range(3)), f"{hint}a")
    R = R_link
    if pose.rotation != Transform().rotation:
        R = tuple(b.define_all(row, f"{hint}R{k}") for k, row in
                  enumerate(matmul(R_link, pose.rotation)))
    return {"p": p, "R": R, "Jlin": Jlin, "Jang": J[3:, :], "w": w, "a": a, "al": al}


def _row(vector, e) -> sp.Expr:
    return sp.Add(*[x * y for x, y in zip(vector, e)])


def loop_program(derivation) -> tuple[list, list, list]:
    """``(Φ, J rows, J̇ q̇)`` of every loop of the model (module docstring), in ``LOOP_ROWS``
    order, in intermediates of the derivation's builder (built once per derivation)."""
    if "loops" in derivation.shared:
        return derivation.shared["loops"]
    model = derivation.model
    if not model.loops:
        raise GenerationError(
            f"{model.source}: loop outputs (loop_constraint, loop_jacobian, loop_bias) need "
            f"loops, and robot '{model.name}' has none: declare them in a scene "
            "(loops: [{name: <name>, type: point, a: {link: <link>}, b: {link: <link>}}])")
    b, qd = derivation.builder, derivation.qd
    links = tuple(dict.fromkeys(f.link for loop in model.loops for f in (loop.a, loop.b)))
    kin = frame_kinematics(model, derivation.tree, derivation.q, qd, b, links)
    n = len(qd)
    Phi, J, bias = [], [], []
    for k, loop in enumerate(model.loops):
        A = _shifted(kin[links.index(loop.a.link)], loop.a.pose, qd, b, f"lA{k}_")
        B = _shifted(kin[links.index(loop.b.link)], loop.b.pose, qd, b, f"lB{k}_")
        if loop.plane is None:
            axes = [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
        else:
            axes = list(plane_axes(loop.plane))
        for e in axes:
            Phi.append(_row([B["p"][i] - A["p"][i] for i in range(3)], e))
            J.append([_row([B["Jlin"][i, c] - A["Jlin"][i, c] for i in range(3)], e)
                      for c in range(n)])
            bias.append(_row([B["a"][i] - A["a"][i] for i in range(3)], e))
        if loop.kind == WELD or (loop.kind == HINGE and loop.plane is None):
            dw = [B["w"][i] - A["w"][i] for i in range(3)]
            dal = [B["al"][i] - A["al"][i] for i in range(3)]
            columns = [[B["Jang"][i, c] - A["Jang"][i, c] for i in range(3)] for c in range(n)]
        if loop.kind == WELD:
            RA, RB = A["R"], B["R"]
            terms = [cross(tuple(RA[r][c] for r in range(3)), tuple(RB[r][c] for r in range(3)))
                     for c in range(3)]
            half = [sp.Rational(1, 2) * sp.Add(*[t[i] for t in terms]) for i in range(3)]
            normal = [tuple(_exact(x) for x in loop.plane)] if loop.plane is not None else None
            for e in normal or [(1, 0, 0), (0, 1, 0), (0, 0, 1)]:
                Phi.append(_row(half, e))
                J.append([_row(col, e) for col in columns])
                bias.append(_row(dal, e))
        elif loop.kind == HINGE and loop.plane is None:
            axis = tuple(_exact(x) for x in loop.axis)
            kA = matvec(A["R"], axis)
            kB = matvec(B["R"], axis)
            kxk = cross(kA, kB)
            for i, t in enumerate(plane_axes(axis)):
                u = b.define_all(matvec(A["R"], t), f"lu{k}_{i}_")
                Phi.append(_row(kxk, u))
                J.append([_row(col, u) for col in columns])
                bias.append(_row(dal, u) + _row(cross(A["w"], u), dw))
    names = loop_rows(model)
    Phi = [b.define(x, f"Phi_{i}") for i, x in enumerate(Phi)]
    J = [[b.define(x, f"Jl{i}_{c + 1}") for c, x in enumerate(row)] for i, row in enumerate(J)]
    bias = [b.define(x, f"dJl{i}_") for i, x in enumerate(bias)]
    assert len(Phi) == len(names)
    derivation.shared["loops"] = (Phi, J, bias)
    return Phi, J, bias


@builds("J_c", "Phi_l", "J_l", "dJqd_l", "dJqd_c")
def build_constraints(derivation, wanted) -> dict:
    """The builder of the loop outputs and of the constrained rows (:mod:`eomgen.outputs`):

    * ``Phi_l`` (m_l,), ``J_l`` (m_l×n), ``dJqd_l`` (m_l,): the loops' rows (module
      docstring), ``LOOP_ROWS`` order;
    * ``J_c`` (m×n) and ``dJqd_c`` (m,): the contacts' rows
      (:func:`eomgen.symbolic.frames.build_contacts`), then the loops' rows.

    Raises
    ------
    GenerationError
        For loop outputs of a model without loops, or constrained rows of a model with neither
        contacts nor loops.
    """
    model = derivation.model
    result = {}
    contact = {"J_c", "dJqd_c"} & set(wanted)
    if contact and (model.contacts or not model.loops):
        result = build_contacts(derivation, contact)
    if model.loops and (set(wanted) & set(LOOP_SYMBOLS) or contact):
        Phi, J, bias = loop_program(derivation)
        loops = {"Phi_l": sp.Matrix(Phi), "J_l": sp.Matrix(J), "dJqd_l": sp.Matrix(bias)}
        for symbol, rows in (("J_c", loops["J_l"]), ("dJqd_c", loops["dJqd_l"])):
            if symbol in contact:
                result[symbol] = sp.Matrix.vstack(result[symbol], rows) if symbol in result \
                    else rows
        result.update({s: loops[s] for s in LOOP_SYMBOLS if s in wanted})
    elif set(wanted) & set(LOOP_SYMBOLS):
        loop_program(derivation)  # raises: no loops
    return result


__all__ = ["LOOP_SYMBOLS", "plane_axes", "loop_rows", "constraint_rows", "constraint_row_count",
           "loop_constants", "parallel_constants", "constraint_constants", "loop_program", "build_constraints"]
