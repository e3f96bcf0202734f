"""Inverse dynamics τ = M q̈ + C q̇ + g by a symbolic recursive Newton–Euler pass.

The recursion is O(n) and yields far fewer operations than forming M q̈ + C q̇ + g from the
matrices, so the generated τ functions use it; verification checks that it equals
the Lagrangian M q̈ + C q̇ + g.

Frames and conventions: every body quantity is in its own body frame (the joint frame after the
joint has moved, see :mod:`eomgen.model`). ``ω``, ``ω̇`` are the body's angular velocity and
acceleration, ``a`` the linear acceleration of the body-frame origin, with gravity entering as a
base acceleration ``a_0 = −g_vec``. Body inertial parameters are about the body origin (m, h, I_O,
see :mod:`eomgen.model.bodies`). With Khalil's matrix ``U = [ω̇]× + [ω]×[ω]×`` (so that the
acceleration of a point at ``r`` on the body is ``a + U r``), the net force and moment about the
origin are

    f = m a + U h,
    n = I_O ω̇ + ω × (I_O ω) + h × a,

and the joint torque is ``τ_i = k_i · n_i`` (revolute), ``k_i · f_i`` (prismatic) or
``k_i · n_i + λ_i k_i · f_i`` (helical of pitch ``λ_i``), ``k_i`` the unit joint axis in body
coordinates. ``U`` costs 6 products of ω's components once per body and
is shared by ``U h`` and by the children's origin accelerations ``a + U r``.

Leaner programs (Khalil and Kleinfinger's customised Newton–Euler): besides the structural zeros
of rotations, offsets and inertias, which SymPy folds, the inertial parameters are **regrouped**
before the recursion (:func:`grouped_inertials`): the part of a body's parameters that looks the
same at every angle of its joint (for a revolute joint about ``k``: the mass, the first moment
along ``k`` and an inertia ``β (1 − k kᵀ)``; for a helical joint that inertia alone; for a
prismatic joint: the rotational inertia) moves
to the parent body, and off a root body into the fixed base, where it does nothing. The joint
efforts are exactly those of the original parameters (the moved part's kinetic and potential
energy do not depend on that joint's position or rate), while most bodies lose their mass and
three of their ten parameters become zero.

Three more choices make the program shorter without changing any effort:

* the moment ``I ω̇ + ω × (I ω)`` is written with the entries of U and the products ω_r ω_c
  that U already names (:func:`_euler_moment`), 5 products per component at most;
* a body without children is described in axes turned about its joint axis so that its first
  moment lies on one axis (:func:`leaf_phases`); its joint angle enters as ``q + φ``;
* when every number is known, the linear accelerations ``a`` are carried divided by the most
  frequent offset length L (:func:`acceleration_length`), so that offsets of that length cost no
  product in ``a + U r``; ``m a`` and ``h × a`` take L into their constants.

Measured with :mod:`eomgen.symbolic.opcount` (``python benchmarks/complexity.py --robots``):
the Panda's τ costs 598 operations, the PUMA 560's 324.
"""

from __future__ import annotations

import sympy as sp
from mpmath.libmp import prec_to_dps

from ..model.bodies import BodyTree, InertialParameters
from ..model import Transform, Vec3
from .builders import builds
from .program import ProgramBuilder, name_expr, name_exprs
from .spatial import (JointFrames, aligned_axis, cross, dot, joint_subspace, matvec, mul, rotation,
                      skew)


def _invariant_part(joint, par: InertialParameters) -> InertialParameters:
    """The part of ``par`` that is the same at every position of the joint (see module doc).

    Revolute about the unit axis ``k``: mass m, first moment (h·k) k and inertia β (1 − k kᵀ),
    with β the inertia about the first body axis after ``k`` when ``k`` is a coordinate axis
    (making that entry zero on the body) and 0 otherwise. Prismatic: the inertia I_O alone.
    Helical: the inertia β (1 − k kᵀ) alone (a mass moves along the axis with the screw).
    """
    zero = sp.Integer(0)
    if not joint.rotates:
        return InertialParameters(zero, (zero,) * 3, par.inertia)
    k = tuple(joint.axis)
    along = dot(k, par.first_moment)
    aligned = aligned_axis(k)
    beta = par.inertia[(aligned[0] + 2) % 3][(aligned[0] + 2) % 3] if aligned else zero
    inertia = tuple(tuple(beta * ((1 if r == c else 0) - k[r] * k[c]) for c in range(3))
                    for r in range(3))
    if joint.lead != 0:
        return InertialParameters(zero, (zero,) * 3, inertia)  # type: ignore[arg-type]
    return InertialParameters(par.mass, tuple(along * x for x in k), inertia)  # type: ignore


def grouped_inertials(tree: BodyTree) -> list[InertialParameters]:
    """Body inertial parameters regrouped so that the joint efforts stay exactly the same.

    Walking from the leaves to the root, each body hands the part of its parameters that its own
    joint cannot move (:func:`_invariant_part`) to its parent, expressed in the parent frame
    through the joint placement; a root body hands it to the fixed base, which drops it. The
    result gives the same τ(q, q̇, q̈) as ``tree``'s own parameters for every state, with fewer
    non-zero parameters (Khalil and Kleinfinger's grouping of inertial parameters).

    Returns
    -------
    list of InertialParameters
        One per body of ``tree``, in its order, about the body origin in body coordinates.
    """
    params = [body.inertial for body in tree.bodies]
    for i in reversed(range(len(tree.bodies))):
        body = tree.bodies[i]
        moved = _invariant_part(body.joint, params[i])
        if moved.is_zero:
            continue
        params[i] = params[i] + _negated(moved)
        if body.parent >= 0:
            placement = Transform(body.placement.rotation, body.placement.translation)
            params[body.parent] = params[body.parent] + moved.transformed(placement)
    return [_folded(p) for p in params]


def leaf_phases(tree: BodyTree, inertials: list) -> tuple[list, dict]:
    """A body frame turned about the joint axis of each leaf body so that its first moment
    lies on one axis: one product fewer in each of ``U h`` and ``h × a``.

    A body without children may be described in any frame turned about its joint axis ``k``
    by a constant angle φ: the joint rotation becomes ``Rot(k, q + φ)`` and nothing else moves.
    With φ chosen so that the first moment ``h`` (perpendicular to ``k`` after
    :func:`grouped_inertials`) points along the first axis after ``k``, ``U h`` needs one column
    of U instead of two and ``h × a`` two products instead of four. The turned inertia is
    regrouped (its invariant part moves to the parent), so the body keeps its number of
    non-zero parameters (a helical joint's body keeps its first moment along ``k``). Only for
    revolute and helical joints about a coordinate axis and numeric first moments with both
    perpendicular components non-zero; other bodies keep φ = 0.

    Returns
    -------
    (list of InertialParameters, dict)
        The parameters (``inertials`` where unchanged) and ``{body index: φ}`` [rad].
    """
    inertials = list(inertials)
    parents = {body.parent for body in tree.bodies}
    phases = {}
    for i, body in enumerate(tree.bodies):
        aligned = aligned_axis(body.joint.axis)
        if i in parents or not body.joint.rotates or aligned is None:
            continue
        a, sign = aligned
        x, y = (a + 1) % 3, (a + 2) % 3
        h = inertials[i].first_moment
        if not (h[x].is_Number and h[y].is_Number and h[x] != 0 and h[y] != 0):
            continue
        # in the numbers' own precision (a high-precision model stays exact to its digits)
        length = sp.sqrt(h[x] ** 2 + h[y] ** 2)
        digits = prec_to_dps(min(v._prec for v in (h[x], h[y]) if v.is_Float) if
                             h[x].is_Float or h[y].is_Float else 53)
        phi = (sign * sp.atan2(h[y], h[x])).evalf(digits)
        turn = rotation(body.joint.axis, h[x] / length, sign * h[y] / length)
        turned = inertials[i].transformed(Transform(tuple(zip(*turn)), (0, 0, 0)))
        first = [sp.Integer(0)] * 3
        first[x] = length  # and h[y] is now exactly 0
        if h[a] != 0:  # a helical joint's body keeps its first moment along the axis
            first[a] = h[a]
        turned = InertialParameters(turned.mass, tuple(first), turned.inertia)
        moved = _invariant_part(body.joint, turned)
        inertials[i] = _folded(turned + _negated(moved))
        if body.parent >= 0:
            placement = Transform(body.placement.rotation, body.placement.translation)
            inertials[body.parent] = _folded(inertials[body.parent]
                                             + moved.transformed(placement))
        phases[i] = phi
    return inertials, phases


def acceleration_length(tree: BodyTree, inertials: list, gravity: Vec3) -> sp.Expr:
    """The length L [m] that :func:`inverse_dynamics_program` divides every linear acceleration
    by (1 when it does not).

    A child's origin acceleration ``a + U r`` costs one product per non-zero offset component
    ``r_j`` and row. Carried as ``a / L``, it reads ``a/L + U (r/L)``, and an offset component
    with ``|r_j| = L`` costs none. The users of ``a`` (``m a`` and ``h × a``) take the factor L
    into their constant factors for free. L is the most frequent offset length among the bodies
    with a moving parent, when the tree has only revolute joints and every offset, inertial
    parameter and gravity component is a number (otherwise 1: a symbolic or a prismatic factor
    would cost products)."""
    one = sp.Integer(1)
    if not all(body.joint.lead == 0 for body in tree.bodies):  # a joint translates
        return one
    numbers = [*gravity, *(x for body in tree.bodies for x in body.placement.translation)]
    for par in inertials:
        numbers += [par.mass, *par.first_moment, *(x for row in par.inertia for x in row)]
    if not all(sp.sympify(x).is_Number for x in numbers):
        return one
    counts: dict = {}
    for body in tree.bodies:
        if body.parent >= 0:
            for x in body.placement.translation:
                if x != 0:
                    counts[abs(x)] = counts.get(abs(x), 0) + 1
    if not counts:
        return one
    return max(counts, key=lambda v: counts[v])  # first seen among the most frequent


def _scaled(x, length):
    """``x / L``, exactly ±1 when ``|x| = L``."""
    if length != 1 and x.is_Number and abs(x) == length:
        return sp.Integer(1 if x > 0 else -1)
    return x / length


def _negated(par: InertialParameters) -> InertialParameters:
    return InertialParameters(-par.mass, tuple(-x for x in par.first_moment),  # type: ignore
                              tuple(tuple(-x for x in row) for row in par.inertia))  # type: ignore


def _folded(par: InertialParameters) -> InertialParameters:
    """Entries expanded, so that a parameter minus itself is an exact zero."""
    return InertialParameters(sp.expand(par.mass), tuple(sp.expand(x) for x in par.first_moment),  # type: ignore
                              tuple(tuple(sp.expand(x) for x in row) for row in par.inertia))  # type: ignore


def _omega_products(w, b: ProgramBuilder, tag) -> tuple:
    """The products ``ww[r][c] = ω_r ω_c`` named (only those used survive), as a symmetric 3×3
    nested tuple."""
    ww = [[name_expr(b, w[r] * w[c], f"ww{tag}_{r}{c}", ("ww", tag, r, c)) for c in range(3)]
          for r in range(3)]
    for r in range(3):
        for c in range(r):
            ww[r][c] = ww[c][r]
    return tuple(tuple(row) for row in ww)


def _renamed_terms(expr, w, ww) -> sp.Expr:
    """``expr`` with each term ``c·t`` (c a number) whose ``t`` is a product ``ω_r ω_c`` of
    ``w`` (up to a number) written with its name from ``ww``."""
    names = {}
    for r in range(3):
        for c in range(3):
            coeff, product = (w[r] * w[c]).as_coeff_Mul()
            if coeff != 0:
                names[product] = ww[r][c] / coeff
    out = []
    for term in sp.Add.make_args(expr):
        coeff, rest = term.as_coeff_Mul()
        out.append(coeff * names[rest] if rest in names else term)
    return sp.Add(*out)


def _khalil_U(ww, dw, b: ProgramBuilder, tag) -> tuple:
    """U = [ω̇]× + [ω]×[ω]× = [ω̇]× + ω ωᵀ − |ω|² 1 from the products ``ww`` of
    :func:`_omega_products`, entries named (only those used survive)."""
    W = skew(dw)
    U = []
    for r in range(3):
        row = []
        for c in range(3):
            if r == c:  # −(ω_j² + ω_k²), named without its sign
                e = -b.define(sum((ww[x][x] for x in range(3) if x != r), sp.Integer(0)),
                              f"U{tag}_{r}{c}", ("U", tag, r, c))
            else:
                e = name_expr(b, ww[r][c] + W[r][c], f"U{tag}_{r}{c}", ("U", tag, r, c))
            row.append(e)
        U.append(tuple(row))
    return tuple(U)


def _euler_moment(I, dw, U, ww, b: ProgramBuilder, tag) -> tuple:
    """I ω̇ + ω × (I ω) about the body origin, written with Khalil's U and the products
    ``ww[r][c] = ω_r ω_c`` that U already names:

        N_i = I_ii ω̇_i − I_ij U_ki + I_ik U_ji + I_jk (ω_j² − ω_k²) + (I_kk − I_jj) ω_j ω_k

    for (i, j, k) a cyclic permutation of (x, y, z). Each off-diagonal inertia multiplies one
    entry of U (``ω_k ω_i − ω̇_j`` or ``ω_j ω_i + ω̇_k``) instead of a component of ω̇ and one of
    ω × Iω, so a component costs at most 5 products instead of the 8 of ``I ω̇ + ω × (I ω)``
    with ``I ω`` formed first. A difference of squares used is named ``wd<body>_<i>``."""
    out = []
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        squares = 0
        if I[j][k] != 0:
            squares = I[j][k] * name_expr(b, ww[j][j] - ww[k][k], f"wd{tag}_{i}", ("wd", tag, i))
        out.append(mul(I[i][i], dw[i]) - mul(I[i][j], U[k][i]) + mul(I[i][k], U[j][i]) + squares
                   + mul(I[k][k] - I[j][j], ww[j][k]))
    return tuple(out)


def inverse_dynamics_program(tree: BodyTree, q, qd, qdd, gravity: Vec3, b: ProgramBuilder,
                             hint: str = "tau") -> sp.Matrix:
    """Build τ(q, q̇, q̈) into ``b``; returns the n×1 matrix of joint efforts [N m or N].

    ``qd`` and ``qdd`` may hold zeros: at ``q̇ = q̈ = 0`` the program is the gravity vector
    ``g(q) = τ(q, 0, 0)``. ``hint`` names the efforts (``tau1`` …, or ``g1`` … for g)."""
    n = len(tree.bodies)
    omega, domega, acc, sincos, khalil = [], [], [], [], []
    zero = (sp.Integer(0),) * 3
    zero33 = (zero, zero, zero)
    inertials, phases = leaf_phases(tree, grouped_inertials(tree))

    frames = JointFrames(tree, q, sincos)  # sincos is filled body by body below
    to_body, to_parent, offset = frames.to_body, frames.to_parent, frames.offset

    # linear accelerations are carried divided by a length L (acceleration_length) [1/s²]
    length = acceleration_length(tree, inertials, gravity)
    base_acc = tuple(-x / length for x in gravity)
    for i, body in enumerate(tree.bodies):
        k = body.q_index
        tag = k + 1
        z = body.joint.axis
        if body.joint.rotates:
            angle = q[k]
            if i in phases:  # the leaf's turned frame (leaf_phases)
                angle = b.define(q[k] + phases[i], f"qp{tag}", ("qp", tag))
            sincos.append((name_expr(b, sp.sin(angle), f"s{tag}", ("s", tag)),
                           name_expr(b, sp.cos(angle), f"c{tag}", ("c", tag))))
        else:
            sincos.append(None)
        if body.parent < 0:
            w_p, dw_p, a_p, U_p = zero, zero, base_acc, zero33
        else:
            p = body.parent
            w_p, dw_p, a_p, U_p = omega[p], domega[p], acc[p], khalil[p][0]
        # origin acceleration of this body in the parent frame: a_p + U_p r
        Ur = matvec(U_p, tuple(_scaled(x, length) for x in offset(i)))
        a_o = name_exprs(b, tuple(a_p[j] + Ur[j] for j in range(3)), f"ap{tag}_", ("ap", tag),
                        scaled=True)
        lead = body.joint.lead
        if body.joint.rotates:
            if lead == 0:
                a = name_exprs(b, to_body(i, a_o), f"a{tag}_", ("a", tag))
            w_in = name_exprs(b, to_body(i, w_p), f"wp{tag}_", ("wp", tag))
            if lead != 0:  # helical: the origin slides λ q along z too (ω × z is ω_in × z)
                s = joint_subspace(body.joint)[1]
                cor = cross(w_in, tuple(2 * s[j] * qd[k] for j in range(3)))
                a = name_exprs(b, tuple(e + cor[j] + s[j] * qdd[k] for j, e in
                                       enumerate(to_body(i, a_o))), f"a{tag}_", ("a", tag))
            w = name_exprs(b, tuple(w_in[j] + z[j] * qd[k] for j in range(3)), f"w{tag}_",
                          ("w", tag))
            ww = _omega_products(w, b, tag)
            # q̇ (ω_in × k): a product that is also some ω_r ω_c (ω's component along k is q̇
            # alone when the parent's ω has none there) uses that product's name
            dw_rel = tuple(_renamed_terms(e, w, ww) for e in
                           cross(w_in, tuple(z[j] * qd[k] for j in range(3))))
            dw = name_exprs(b, tuple(e + dw_rel[j] + z[j] * qdd[k] for j, e in
                                    enumerate(to_body(i, dw_p))), f"dw{tag}_", ("dw", tag))
        else:
            w = name_exprs(b, to_body(i, w_p), f"w{tag}_", ("w", tag))
            ww = _omega_products(w, b, tag)
            dw = name_exprs(b, to_body(i, dw_p), f"dw{tag}_", ("dw", tag))
            cor = cross(w, tuple(2 * z[j] * qd[k] for j in range(3)))
            a = name_exprs(b, tuple(e + cor[j] + z[j] * qdd[k] for j, e in
                                   enumerate(to_body(i, a_o))), f"a{tag}_", ("a", tag))
        omega.append(w)
        domega.append(dw)
        acc.append(a)
        khalil.append((_khalil_U(ww, dw, b, tag), ww))

    force: list = [None] * n
    moment: list = [None] * n
    for i, body in enumerate(tree.bodies):
        tag = body.q_index + 1
        par = inertials[i]
        m, h, I = par.mass, par.first_moment, par.inertia
        w, dw, a = omega[i], domega[i], acc[i]
        U, ww = khalil[i]
        Uh = matvec(U, h)
        f = tuple(m * length * a[j] + Uh[j] for j in range(3))
        nn = tuple(x + y for x, y in zip(_euler_moment(I, dw, U, ww, b, tag),
                                         cross(tuple(x * length for x in h), a)))
        force[i] = list(f)
        moment[i] = list(nn)

    tau = sp.zeros(n, 1)
    for i in reversed(range(n)):
        body = tree.bodies[i]
        tag = body.q_index + 1
        f = name_exprs(b, force[i], f"f{tag}_", ("f", tag), scaled=True)
        nn = name_exprs(b, moment[i], f"n{tag}_", ("n", tag), scaled=True)
        axis = body.joint.axis
        effort = dot(axis, nn if body.joint.rotates else f)
        if body.joint.rotates and body.joint.lead != 0:  # helical: n·k + λ f·k
            effort = effort + dot(joint_subspace(body.joint)[1], f)
        tau[body.q_index, 0] = name_expr(b, effort, f"{hint}{tag}", ("effort", tag))
        p = body.parent
        if p >= 0:
            f_p = name_exprs(b, to_parent(i, f), f"fp{tag}_", ("fp", tag))
            n_p = to_parent(i, nn)
            rf = cross(offset(i), f_p)
            for j in range(3):
                force[p][j] = force[p][j] + f_p[j]
                moment[p][j] = moment[p][j] + n_p[j] + rf[j]
    return tau


@builds("tau")
def build_inverse_dynamics(derivation, wanted) -> dict:
    """The builder of ``tau`` in :mod:`eomgen.outputs`: :func:`inverse_dynamics_program`."""
    return {"tau": inverse_dynamics_program(derivation.tree, derivation.q, derivation.qd,
                                            derivation.qdd, derivation.model.gravity,
                                            derivation.builder)}
