"""The joint torque regressor τ = Y(q, q̇, q̈) π as a straight-line program.

Inverse dynamics is linear in the inertial parameters. Per moving body j (a :class:`~eomgen.model.bodies.
RigidBody`: the child link of a movable joint with its fixed descendants merged) the ten
parameters, in Pinocchio's order (``Inertia.toDynamicParameters``), are::

    π_j = (m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz)

with ``c`` the centre of mass and ``I`` the rotational inertia *about the body frame origin*, all
in body-frame coordinates. The body frame is the frame of the movable joint after it has moved
(= the frame of the joint's child link, URDF's convention; for DH input, DH frame j). Links fixed
to it are merged into it (their parameters moved into this frame), exactly as Pinocchio's URDF
reader appends them to the joint; links fixed to the root carry no column.

Derivation (the principle of virtual power, one body at a time). Let ``s_i^j`` be the motion axis
of joint i expressed in body j's frame at body j's origin (angular part first): ``s_i^i = (z_i, 0)``
for a revolute joint, ``(0, z_i)`` for a prismatic one, and ``s_i^j = X_{j←p(j)} s_i^{p(j)}`` down
the tree. Body j's wrench about its origin, ``n = I ω̇ + ω × I ω + h × a``,
``f = m a + ω̇ × h + ω × (ω × h)`` (``a`` the origin's acceleration with gravity as a base
acceleration ``−g_vec``), is ``A_j(ω, ω̇, a) π_j``; the torque it demands at joint i is
``s_i^jᵀ A_j π_j``, so ``Y_{i, j} = s_i^jᵀ A_j`` for i an ancestor of (or equal to) j, 0 otherwise.
With ``s = (ω_s, v_s)`` the ten entries are::

    m: v_s · a
    h: a × ω_s − ω̇ × v_s + ω × (ω × v_s)                   (three entries)
    I: ω_sᵀ E ω̇ + (ω_s × ω)ᵀ E ω   for the six symmetric unit matrices E

Energies are linear in π too: ``K_j = ½ m |v|² + h · (v × ω) + ½ ωᵀ I ω`` (``v`` the origin's
velocity) and ``P_j = −m g_vec · p_j − (R_jᵀ g_vec) · h`` (``p_j``, ``R_j`` the body's pose in the
root frame), so ``K = Y_K(q, q̇) π`` and ``P = Y_P(q) π`` (1 × p rows).

Optional actuator columns per joint k: armature ``I_a`` (column q̈_k), viscous friction ``f_v``
(q̇_k), Coulomb friction ``f_c`` (sign q̇_k), offset ``f_o`` (1); they enter row k only and are
not part of K and P.
"""

from __future__ import annotations

import sympy as sp

from ..model.bodies import BodyTree
from .program import ProgramBuilder
from .spatial import JointFrames, cross, dot, joint_subspace

#: Column names of one body's block, Pinocchio's order; the joint number (1-based, JOINT_NAMES
#: order) is appended: ``M1, MX1, …`` (Khalil's names: mass, first moments, inertia about the
#: body origin).
INERTIAL_NAMES = ("M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ")
#: Actuator parameters: armature [kg m² or kg], viscous [N m s/rad or N s/m], Coulomb and
#: offset [N m or N], with the column each contributes to its joint's row.
ACTUATOR_NAMES = {"armature": "IA", "viscous": "FV", "coulomb": "FC", "offset": "FO"}
ACTUATOR_TERMS = tuple(ACTUATOR_NAMES)

# (row, col) pairs of the six inertia parameters, Pinocchio's order xx, xy, yy, xz, yz, zz
_INERTIA_ENTRIES = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))


def _sym_times(r: int, c: int, x, y) -> sp.Expr:
    """xᵀ E y for the symmetric unit matrix E with ones at (r, c) and (c, r)."""
    if r == c:
        return x[r] * y[r]
    return x[r] * y[c] + x[c] * y[r]


def regressor_program(tree: BodyTree, q, qd, qdd, gravity, b: ProgramBuilder,
                      actuators=()) -> dict:
    """Build Y (n × p), Y_K (1 × p) and Y_P (1 × p) into ``b``.

    Parameters
    ----------
    tree:
        The moving bodies.
    q, qd, qdd:
        Joint symbols in JOINT_NAMES order.
    gravity:
        Gravitational acceleration in the root frame [m/s²].
    actuators:
        Subset of :data:`ACTUATOR_TERMS`; their columns follow the 10 n inertial ones, one group
        of n per term in the order given.

    Returns
    -------
    dict
        ``"Y"``, ``"K"``, ``"P"``: SymPy matrices in the intermediates of ``b``.
    """
    n = len(tree.bodies)
    p = 10 * n + len(actuators) * n
    zero3 = (sp.Integer(0),) * 3
    sincos: list = []

    to_body = JointFrames(tree, q, sincos).to_body  # sincos is filled body by body below

    def offset(i):
        """Body i's origin in its parent's frame (moves with a prismatic or helical joint)."""
        body = tree.bodies[i]
        r = body.placement.translation
        lead = body.joint.lead
        if lead == 0:
            return r
        R = body.placement.rotation
        z = body.joint.axis
        move = q[body.q_index] if lead == 1 else lead * q[body.q_index]
        return tuple(r[a] + sp.Add(*[R[a][k] * z[k] for k in range(3)]) * move
                     for a in range(3))

    omega, domega, acc, vel, grav, height = [], [], [], [], [], []
    for i, body in enumerate(tree.bodies):
        k = body.q_index
        tag = k + 1
        z = body.joint.axis
        revolute = body.joint.rotates
        sincos.append((b.define(sp.sin(q[k]), f"s{tag}"), b.define(sp.cos(q[k]), f"c{tag}"))
                      if revolute else None)
        if body.parent < 0:
            w_p, dw_p, a_p, v_p = zero3, zero3, tuple(-x for x in gravity), zero3
            g_p, h_p = tuple(gravity), sp.Integer(0)
        else:
            j = body.parent
            w_p, dw_p, a_p, v_p, g_p, h_p = (omega[j], domega[j], acc[j], vel[j], grav[j],
                                             height[j])
        r = offset(i)
        wr = cross(w_p, r)
        v_o = tuple(v_p[a] + wr[a] for a in range(3))
        a_o = tuple(a_p[a] + x + y for a, (x, y) in
                    enumerate(zip(cross(dw_p, r), cross(w_p, wr))))
        w_in = b.define_all(to_body(i, w_p), f"wp{tag}_")
        dw_in = to_body(i, dw_p)
        a_in = to_body(i, b.define_all(a_o, f"ap{tag}_"))
        v_in = to_body(i, b.define_all(v_o, f"vp{tag}_"))
        if revolute:
            w = b.define_all(tuple(w_in[a] + z[a] * qd[k] for a in range(3)), f"w{tag}_")
            rel = cross(w_in, tuple(z[a] * qd[k] for a in range(3)))
            dw = b.define_all(tuple(dw_in[a] + rel[a] + z[a] * qdd[k] for a in range(3)),
                              f"dw{tag}_")
            if body.joint.lead == 0:
                a_ = b.define_all(a_in, f"a{tag}_")
                v = b.define_all(v_in, f"v{tag}_")
            else:  # helical: the origin slides λ q along z too (ω × z is ω_in × z)
                s = joint_subspace(body.joint)[1]
                cor = cross(w_in, tuple(2 * s[a] * qd[k] for a in range(3)))
                a_ = b.define_all(tuple(a_in[a] + cor[a] + s[a] * qdd[k] for a in range(3)),
                                  f"a{tag}_")
                v = b.define_all(tuple(v_in[a] + s[a] * qd[k] for a in range(3)), f"v{tag}_")
        else:
            w = w_in
            dw = b.define_all(dw_in, f"dw{tag}_")
            cor = cross(w, tuple(2 * z[a] * qd[k] for a in range(3)))
            a_ = b.define_all(tuple(a_in[a] + cor[a] + z[a] * qdd[k] for a in range(3)),
                              f"a{tag}_")
            v = b.define_all(tuple(v_in[a] + z[a] * qd[k] for a in range(3)), f"v{tag}_")
        omega.append(w)
        domega.append(dw)
        acc.append(a_)
        vel.append(v)
        # gravity in body coordinates and g_vec · (origin position), for the potential energy
        height.append(b.define(h_p + dot(g_p, r), f"gp{tag}"))
        grav.append(b.define_all(to_body(i, g_p), f"gb{tag}_"))

    Y = sp.zeros(n, p)
    YK = sp.zeros(1, p)
    YP = sp.zeros(1, p)
    axes_at: list[dict] = []  # per body j: {ancestor-or-self i: s_i^j}
    for j, body in enumerate(tree.bodies):
        tag = body.q_index + 1
        col = 10 * body.q_index
        w, dw, a_, v = omega[j], domega[j], acc[j], vel[j]
        # energies
        half = sp.Rational(1, 2)
        YK[0, col] = b.define(half * dot(v, v), f"K{tag}_0")
        for e, value in enumerate(cross(v, w)):
            YK[0, col + 1 + e] = b.define(value, f"K{tag}_{1 + e}")
        for e, (r_, c_) in enumerate(_INERTIA_ENTRIES):
            YK[0, col + 4 + e] = b.define(half * _sym_times(r_, c_, w, w), f"K{tag}_{4 + e}")
        YP[0, col] = b.define(-height[j], f"P{tag}_0")
        for e in range(3):
            YP[0, col + 1 + e] = -grav[j][e]
        # torque columns: the motion axis s_i^j of every joint i on the path, in body j's
        # frame at its origin, carried from the parent's (X_{j←p}: rotate, shift by r × ω)
        axes = {j: joint_subspace(body.joint)}
        if body.parent >= 0:
            r = offset(j)
            for anc, (w_s, v_s) in axes_at[body.parent].items():
                v_moved = tuple(v_s[e] + x for e, x in enumerate(cross(w_s, r)))
                t = f"{tree.bodies[anc].q_index + 1}_{tag}"
                axes[anc] = (b.define_all(to_body(j, w_s), f"sw{t}_"),
                             b.define_all(to_body(j, v_moved), f"sv{t}_"))
        axes_at.append(axes)
        for anc, (w_s, v_s) in axes.items():
            row = tree.bodies[anc].q_index
            t = f"{row + 1}_{tag}"
            entries = [dot(v_s, a_)]
            h_col = cross(a_, w_s)
            dv = cross(dw, v_s)
            wwv = cross(w, cross(w, v_s))
            entries += [h_col[e] - dv[e] + wwv[e] for e in range(3)]
            u = b.define_all(cross(w_s, w), f"u{t}_") if any(x != 0 for x in w_s) else zero3
            entries += [_sym_times(r_, c_, w_s, dw) + _sym_times(r_, c_, u, w)
                        for r_, c_ in _INERTIA_ENTRIES]
            for e, value in enumerate(entries):
                Y[row, col + e] = b.define(value, f"Y{row + 1}_{col + e + 1}")
    for g_idx, term in enumerate(actuators):
        for body in tree.bodies:
            k = body.q_index
            value = {"armature": qdd[k], "viscous": qd[k], "coulomb": sp.sign(qd[k]),
                     "offset": sp.Integer(1)}[term]
            Y[k, 10 * n + g_idx * n + k] = value
    return {"Y": Y, "K": YK, "P": YP}
