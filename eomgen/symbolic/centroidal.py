"""Centroidal quantities as straight-line programs: centre of mass, its Jacobian, the
centroidal momentum matrix, its bias and the centroidal composite inertia.

With the world-frame composites of :mod:`eomgen.symbolic.composite` (bodies in world axes about
the reference point o, joint motions ``S_j`` about o), the momentum of the robot about o is
``h_o = Σ_j F_j q̇_j``, ``F_j = I^c_j S_j`` (I^c_j the composite inertia of j's subtree). About
the centre of mass ``c`` (from o) the linear momentum is the same and the angular momentum is
``n_o − c × f``, so (Pinocchio's conventions, rows linear first, world axes, about the CoM):

* ``c_G`` (3,): the centre of mass in world coordinates [m] (``pinocchio.centerOfMass``);
* ``J_G`` (3×NV): ``ċ = J_G v`` (``jacobianCenterOfMass``), the linear rows of A_G over m;
* ``A_G`` (6×NV): ``h_G = A_G v = [m ċ; angular momentum about c]`` (``computeCentroidalMap``);
* ``dAGv`` (6,): ``Ȧ_G v``, the rate of ``h_G`` at ``v̇ = 0``
  (``computeCentroidalMapTimeVariation(...) @ v``): from ``ḣ_o = Σ_i (I_i a_i + V_i ×* I_i V_i)``
  with each body's spatial velocity ``V_i`` and acceleration ``a_i`` at ``v̇ = 0`` (about o),
  shifted to c as the momentum is (``ċ × m ċ = 0``);
* ``I_G`` (6×6): the centroidal composite inertia ``[[m 1, 0], [0, I_c]]`` (``data.Ig``), I_c
  the rotational inertia of the whole robot about its centre of mass, world axes.

The centroidal equations ``ḣ_G = A_G v̇ + Ȧ_G v = Σ external wrenches about c + [m g; 0]`` are
what a legged robot's planner uses. Where the configuration is not the coordinates (a free
flyer, a ball joint) the chart's ``Ȧ_G v`` is corrected by ``A_G n(v)``
(:mod:`eomgen.symbolic.charts`). Units: SI.
"""

from __future__ import annotations

import sympy as sp

from .builders import builds
from .composite import world_composites
from .charts import chart_offset
from .spatial import cross, force_cross, motion_cross


def _motions(tree, kin, qd, b) -> tuple[list, list]:
    """Each body's spatial velocity and acceleration at q̈ = 0, world axes about o."""
    V, A = [], []
    for i, body in enumerate(tree.bodies):
        rate = qd[body.q_index]
        V0, A0 = (V[body.parent], A[body.parent]) if body.parent >= 0 else ((0,) * 6,) * 2
        Vi = b.define_all(tuple(V0[r] + kin.S[i][r] * rate for r in range(6)), f"Vc{i + 1}_")
        VxS = motion_cross(Vi, kin.S[i])
        A.append(b.define_all(tuple(A0[r] + VxS[r] * rate for r in range(6)), f"Ac{i + 1}_"))
        V.append(Vi)
    return V, A


def base_momentum(derivation) -> tuple[list, sp.Matrix]:
    """The centre of mass (world) and A_G of a model on a virtual base joint (the free flyer,
    :attr:`~eomgen.model.RobotModel.base_kind`) from the first six rows of M:
    with the root twist as the first velocities, ``M[0:6, :]`` is the robot's momentum map
    about the root origin in root axes (force rows first), and ``M[0:3, 3:6] = −m [c_b]×``
    gives the centre of mass ``c_b`` in root axes. Rotated by the root's R and shifted to the
    centre of mass: ``A_G[:, j] = [R f_j; R (n_j − c_b × f_j)]``. Cheaper than the world-frame
    composites when M's rows are in the program anyway (solo12: see
    benchmarks/legged_speed.py)."""
    b, M = derivation.builder, derivation.output("M")
    placement = derivation.tree.bodies[0].placement
    R, p = placement.rotation, placement.translation
    inv_mass = b.define(1 / M[0, 0], "inv_mtot", ("mtot",))
    c_b = b.define_all((M[1, 5] * inv_mass, M[2, 3] * inv_mass, M[0, 4] * inv_mass), "cb")
    Rc = [sp.Add(*[R[r][k] * c_b[k] for k in range(3)]) for r in range(3)]
    com = [p[r] + Rc[r] for r in range(3)]
    A_G = sp.zeros(6, M.cols)
    for j in range(M.cols):
        f = [M[r, j] for r in range(3)]
        c_f = cross(c_b, f)
        moment = [M[3 + r, j] - c_f[r] for r in range(3)]
        for r in range(3):
            A_G[r, j] = b.define(sp.Add(*[R[r][k] * f[k] for k in range(3)]), f"AGf{r}_{j + 1}")
            A_G[3 + r, j] = b.define(sp.Add(*[R[r][k] * moment[k] for k in range(3)]),
                                     f"AGn{r}_{j + 1}")
    return com, A_G


@builds("c_G", "J_G", "A_G", "dAGv", "I_G")
def build_centroidal(derivation, wanted) -> dict:
    """The builder of ``c_G``, ``J_G``, ``A_G``, ``dAGv`` and ``I_G`` (module docstring)."""
    tree, b, n = derivation.tree, derivation.builder, derivation.model.dof
    kin, world, comp, F = world_composites(tree, derivation.q, b)
    roots = [i for i, body in enumerate(tree.bodies) if body.parent < 0]
    mass = b.define(sp.Add(*[comp[i].mass for i in roots]), "mtot", ("mtot",))
    first = [sp.Add(*[comp[i].h[r] for i in roots]) for r in range(3)]
    inv_mass = b.define(1 / mass, "inv_mtot", ("mtot",))
    c = b.define_all(tuple(first[r] * inv_mass for r in range(3)), "cG", ("cG",))
    result = {}
    if derivation.model.base_kind is not None and wanted & {"c_G", "A_G", "J_G"}:
        com, A_G = base_momentum(derivation)
    else:
        com = [kin.origin[r] + c[r] for r in range(3)]
        A_G = sp.zeros(6, n)
        for j, body in enumerate(tree.bodies):
            n_o, f = F[j][:3], F[j][3:]
            c_f = cross(c, f)
            for r in range(3):
                A_G[r, body.q_index] = f[r]
                A_G[3 + r, body.q_index] = b.define(n_o[r] - c_f[r], f"AG{r}_{body.q_index + 1}")
    if "c_G" in wanted:
        result["c_G"] = sp.Matrix([b.define(com[r], f"com{r}") for r in range(3)])
    if "A_G" in wanted:
        result["A_G"] = A_G
    if "J_G" in wanted:
        result["J_G"] = A_G[:3, :].applyfunc(lambda e: b.define(e * inv_mass, "JG"))
    if "dAGv" in wanted:
        V, A = _motions(tree, kin, derivation.qd, b)
        rate = [sp.Integer(0)] * 6
        for i in range(len(tree.bodies)):
            IA, IV = world[i].apply(A[i]), world[i].apply(V[i])
            VxIV = force_cross(V[i], IV)
            rate = [rate[r] + IA[r] + VxIV[r] for r in range(6)]
        n_o, f = rate[:3], rate[3:]
        c_f = cross(c, f)
        bias = list(f) + [n_o[r] - c_f[r] for r in range(3)]
        if derivation.model.nq > derivation.model.dof:  # a chart: less A_G n(v)
            offset = chart_offset(derivation, derivation.qd)
            bias = [bias[r] - sp.Add(*[A_G[r, k] * offset[k] for k in range(len(offset))
                                       if offset[k] != 0]) for r in range(6)]
        result["dAGv"] = sp.Matrix(b.define_all(tuple(bias), "dAGv", ("dAGv",)))
    if "I_G" in wanted:
        I_o = [[sp.Add(*[comp[i].I[r][k] for i in roots]) for k in range(3)] for r in range(3)]
        cc = sp.Add(*[x * x for x in c])
        I_G = sp.zeros(6, 6)
        for r in range(3):
            I_G[r, r] = mass
            for k in range(3):
                shift = mass * ((cc if r == k else 0) - c[r] * c[k])
                I_G[3 + r, 3 + k] = b.define(I_o[r][k] - shift, f"IG{min(r, k)}{max(r, k)}")
        result["I_G"] = I_G
    return result


__all__ = ["build_centroidal"]
