"""The textbook Lagrangian derivation, body by body, for teaching-sized models.

For each moving body i (a movable joint's child link with its fixed descendants merged, see
:mod:`eomgen.model.bodies`), in the world (root link) frame:

* ``p_ci(q)``: position of the centre of mass [m];
* ``J_vi = ∂p_ci/∂q`` (3×n) and ``J_ωi`` (3×n): column k is the world axis ``z_k`` of joint k
  when k is a revolute joint at or before body i, else 0; so ``v_ci = J_vi q̇``, ``ω_i = J_ωi q̇``;
* ``K_i = ½ m_i v_ciᵀ v_ci + ½ ω_iᵀ R_i I_ci R_iᵀ ω_i`` with ``I_ci`` the rotational inertia about
  the centre of mass in body axes and ``R_i`` the body's world rotation [J];
* ``P_i = −m_i g_vecᵀ p_ci`` with ``g_vec`` the gravitational acceleration [J];
* ``M = Σ_i m_i J_viᵀ J_vi + J_ωiᵀ R_i I_ci R_iᵀ J_ωi`` (n×n), so that ``K = ½ q̇ᵀ M q̇``;
* the Christoffel symbols of the first kind
  ``c_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)``, with ``C_ij = Σ_k c_ijk q̇_k``;
* ``g_i = ∂P/∂q_i`` with ``P = Σ_i P_i``.

Everything is computed in one sparse polynomial ring over ``sin q_i``, ``cos q_i``, the
parameters and the velocities, reduced with ``sin² + cos² = 1``
(:class:`~eomgen.symbolic.trigonometry.TrigAlgebra`), and written as a textbook
does: products of sines and cosines of the joint angles, or of the absolute angles
``q_2 + q_3`` along chains of parallel revolute axes (whichever has fewer terms), with
``cos²`` or ``sin²`` chosen per parameter group (``I_x2 sin² q_2 + I_y2 cos² q_2``).
Expanded expressions grow exponentially with the number of joints, so this is for models of at
most :data:`TEXTBOOK_MAX_DOF` joints (and, by default, :data:`TEXTBOOK_MAX_OPERATIONS`).
:func:`eomgen.derive` computes the same M, C, g without expression swell; the tests check that
the two agree. (:func:`~eomgen.symbolic.trigonometry.fourier_form` gives the alternative
canonical form, sums of harmonics.)
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.bodies import body_tree
from ..model import IDENTITY3, RobotModel, Transform, ZERO3, all_scalars, joint_motion
from .derivation import joint_symbols
# The algebra the derivation computes in; its functions are also imported from here.
from .trigonometry import (FLOAT_NOISE_RTOL, TrigAlgebra, drop_float_noise, fourier_form,  # noqa: F401
                           largest_coefficient, round_floats, simplify_trig)

#: Largest number of joints for which the textbook derivation is computed by default.
TEXTBOOK_MAX_DOF = 3

#: Largest straight-line program (operations of M, C and g, see
#: :meth:`eomgen.Dynamics.operation_count`) for which the textbook derivation is computed by
#: default: a cheap estimate of its cost, known before anything is expanded. The bundled
#: teaching arms have 400-550 operations and take about a second; a 3-joint arm with general
#: axes and offsets of 1500 operations takes 20 s.
TEXTBOOK_MAX_OPERATIONS = 1200

@dataclass(frozen=True)
class BodyTerms:
    """The textbook quantities of one moving body (n = number of joints).

    Attributes
    ----------
    joint:
        Name of the body's movable joint.
    links:
        Links merged into the body, the joint's child first.
    mass:
        m_i [kg].
    com:
        p_ci, the centre of mass in the world frame (3×1) [m].
    rotation:
        R_i, the world rotation of the body frame (3×3).
    inertia:
        I_ci, rotational inertia about the centre of mass in body axes (3×3) [kg m²].
    J_v, J_w:
        Linear and angular velocity Jacobians of the centre of mass (3×n).
    M:
        The body's share of the mass matrix, ``m J_vᵀ J_v + J_ωᵀ R I_c Rᵀ J_ω`` (n×n).
    K:
        Kinetic energy ``K_i = ½ m v_cᵀ v_c + ½ ωᵀ R I_c Rᵀ ω = ½ q̇ᵀ M_i q̇`` [J], as a sum over
        the products ``q̇_j q̇_k`` (j ≤ k) with simplified coefficients.
    P:
        Potential energy P_i(q) [J].
    """

    joint: str
    links: tuple[str, ...]
    mass: sp.Expr
    com: sp.Matrix
    rotation: sp.Matrix
    inertia: sp.Matrix
    J_v: sp.Matrix
    J_w: sp.Matrix
    M: sp.Matrix
    K: sp.Expr
    P: sp.Expr


@dataclass(frozen=True)
class TextbookDerivation:
    """The body-by-body Lagrangian derivation of a small model (see the module docstring).

    Attributes
    ----------
    q, qd:
        Joint position and velocity symbols (``q1…qn``, ``qd1…qdn``), in joint order.
    gravity:
        g_vec, the gravitational acceleration in the world frame [m/s²].
    bodies:
        One :class:`BodyTerms` per moving body, a parent before its children.
    K, P:
        Total kinetic and potential energy, ``Σ K_i = ½ q̇ᵀ M q̇`` (as a sum over ``q̇_j q̇_k``)
        and ``Σ P_i``, simplified [J].
    M:
        The mass matrix ``Σ_i m_i J_viᵀ J_vi + J_ωiᵀ R_i I_ci R_iᵀ J_ωi`` (n×n), simplified.
    christoffel:
        The non-zero Christoffel symbols ``((i, j, k), c_ijk)`` of M with ``j ≤ k``, 0-based (see
        :func:`christoffel_symbols`; written Γ_ijk in the LaTeX document).
    C:
        The Coriolis matrix ``C_ij = Σ_k c_ijk q̇_k`` (n×n), simplified.
    g:
        The gravity vector ``g_i = ∂P/∂q_i`` (n×1), simplified.
    """

    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    gravity: tuple[sp.Expr, sp.Expr, sp.Expr]
    bodies: tuple[BodyTerms, ...]
    K: sp.Expr
    P: sp.Expr
    M: sp.Matrix
    christoffel: tuple[tuple[tuple[int, int, int], sp.Expr], ...]
    C: sp.Matrix
    g: sp.Matrix
    #: ``(k, p)``: joint k's axis is parallel to that of joint p just before it (0-based), so
    #: results may be written in the absolute angle ``q_p + q_k`` (see :meth:`trig_form`).
    parallel: tuple[tuple[int, int], ...] = ()
    #: The description's floats, printed with all their digits (:func:`description_floats`).
    written: frozenset[float] = frozenset()

    def trig_form(self, matrix) -> sp.Matrix:
        """``matrix`` (entries: polynomials in sines and cosines of the joint angles, in any
        form: ``sin(2 q_2)``, ``cos(q_2 + q_3)``, products) written as this derivation writes
        M, the Christoffel symbols and g: products of ``s_k``, ``c_k`` (and ``s_{23}``,
        ``c_{23}`` of parallel joints where shorter), reduced with ``s² + c² = 1``, float
        noise dropped, common factors pulled out. Never a double angle: one form in every
        section of a document. Other symbols (velocities, a controller's q̇_r) are kept as
        they are.

        >>> import eomgen
        >>> book = textbook_derivation(eomgen.load(eomgen.example_path("planar_2link")))
        >>> q1, q2 = book.q
        >>> book.trig_form(sp.Matrix([sp.sin(2 * q2), sp.cos(q1) * sp.cos(q2) - sp.sin(q1) * sp.sin(q2)]))
        Matrix([
        [2*sin(q2)*cos(q2)],
        [     cos(q1 + q2)]])
        """
        matrix = sp.Matrix(matrix)
        # sin(2 q2) → 2 s2 c2, cos(q2 + q3) → c2 c3 − s2 s3: products of the joints' own sines
        # and cosines, which the algebra reduces and rewrites in the absolute angles
        entries = [sp.expand_trig(sp.sympify(e)) for e in matrix]
        A = TrigAlgebra(entries, self.q, self.qd)
        A.written = self.written
        A.absolute_angles(dict(self.parallel))
        rows = [[A(e) for e in entries[r * matrix.cols:(r + 1) * matrix.cols]]
                for r in range(matrix.rows)]
        if not rows or not rows[0]:
            return matrix
        reference = A.largest(rows)
        return sp.Matrix([[A.expr(f, reference, by_factor=True) for f in row] for row in rows])


def textbook_derivation(model: RobotModel, max_dof: int = TEXTBOOK_MAX_DOF) -> TextbookDerivation:
    """The textbook quantities of every moving body of ``model`` (see the module docstring).

    Parameters
    ----------
    model:
        A robot model; joint symbols are those of :func:`eomgen.derive` (``q1…qn``, ``qd1…qdn``).
    max_dof:
        Refuse larger models: expanded expressions grow exponentially with the number of joints.

    Raises
    ------
    ValueError
        When the model has more than ``max_dof`` movable joints.

    Examples
    --------
    >>> import eomgen
    >>> arm = eomgen.load(eomgen.example_path("planar_2link"))
    >>> book = textbook_derivation(arm)
    >>> book.bodies[1].com.T
    Matrix([[l1*cos(q1) + lc2*cos(q1 + q2), l1*sin(q1) + lc2*sin(q1 + q2), 0]])
    >>> book.bodies[0].P
    g*lc1*m1*sin(q1)
    """

    n = model.dof
    if n > max_dof:
        raise ValueError(f"the textbook derivation is for models of at most {max_dof} joints "
                         f"({model.name!r} has {n})")
    q, qd, _ = joint_symbols(n)
    tree = body_tree(model)

    # The inputs, as SymPy expressions: world pose of every body, centre of mass and inertia.
    poses: list[Transform] = []
    inputs = []
    for body in tree.bodies:
        parent = poses[body.parent] if body.parent >= 0 else Transform(IDENTITY3, ZERO3)
        poses.append(parent @ body.placement @ joint_motion(body.joint, q[body.q_index]))
        par = body.inertial
        m = par.mass
        if m == 0:
            c, I_c = sp.zeros(3, 1), sp.Matrix(par.inertia)
        else:
            c = sp.Matrix(par.first_moment).applyfunc(lambda h: sp.cancel(h / m))
            I_c = sp.Matrix(par.inertia) - m * ((c.T * c)[0, 0] * sp.eye(3) - c * c.T)
        inputs.append((m, c, I_c))
    scalars = [x for pose in poses for row in pose.rotation for x in row]
    scalars += [x for pose in poses for x in pose.translation]
    scalars += [x for m, c, I_c in inputs for x in [m, *c, *I_c]]
    scalars += [x for body in tree.bodies for x in body.joint.axis] + list(model.gravity)
    A = TrigAlgebra(scalars, q, qd)
    A.written = description_floats(model)  # printed with all their digits, never rounded

    # The textbook quantities, computed in the polynomial ring.
    gravity = [A(x) for x in model.gravity]
    zero = A.ring.zero
    axes = []   # world axis of each body's joint (zero for prismatic)
    for body, pose in zip(tree.bodies, poses):
        R = [[A(x) for x in row] for row in pose.rotation]
        axis = [A(x) for x in body.joint.axis]
        axes.append([A.reduce(sum((R[r][k] * axis[k] for k in range(3)), zero))
                     for r in range(3)] if body.joint.rotates else [zero] * 3)
    # Chains of parallel revolute joints (the elbow arm's shoulder and elbow): write results in
    # the absolute angles q2 + q3 where that is shorter.
    parallel = {body.q_index: tree.bodies[body.parent].q_index
                for i, body in enumerate(tree.bodies)
                if body.parent >= 0 and body.joint.type.is_revolute
                and tree.bodies[body.parent].joint.type.is_revolute
                and any(axes[i]) and axes[i] == axes[body.parent]}
    A.absolute_angles(parallel)
    bodies = []
    shares = []
    potentials = []
    for i, (body, pose, (m, c, I_c)) in enumerate(zip(tree.bodies, poses, inputs)):
        R = [[A(x) for x in row] for row in pose.rotation]
        mass = A(m)
        com = [A(c[r]) for r in range(3)]
        p_c = [A(pose.translation[r]) + sum((R[r][k] * com[k] for k in range(3)), zero)
               for r in range(3)]
        J_v = [[A.derivative(p_c[r], k) for k in range(n)] for r in range(3)]
        J_w = [[zero] * n for _ in range(3)]
        for a in [i] + tree.ancestors(i):
            for r in range(3):
                J_w[r][tree.bodies[a].q_index] = axes[a][r]
        inertia = [[A(I_c[r, k]) for k in range(3)] for r in range(3)]
        I_w = [[A.reduce(x) for x in row] for row in A.product(A.product(R, inertia),
                                                                 A.transpose(R))]
        share = [[A.reduce(x) for x in row] for row in
                 A.plus(A.times(mass, A.product(A.transpose(J_v), J_v)),
                        A.product(A.transpose(J_w), A.product(I_w, J_w)))]
        P = -mass * sum((gravity[r] * p_c[r] for r in range(3)), zero)
        shares.append(share)
        potentials.append(P)
        M_i = A.matrix(share)
        bodies.append(BodyTerms(
            body.joint.name, body.links, A.expr(mass), A.matrix([[x] for x in p_c]),
            A.matrix(R, reference=1.0), A.matrix(inertia), A.matrix(J_v),
            A.matrix(J_w, reference=1.0), M_i, quadratic_form(M_i, qd), A.expr(P)))

    M = [[A.ring.zero] * n for _ in range(n)]
    for share in shares:
        M = A.plus(M, share)
    P = sum(potentials, A.ring.zero)
    half = A.ring.domain.convert(sp.Rational(1, 2))
    dM = [[[A.reduce(A.derivative(M[i][j], k)) for j in range(n)] for i in range(n)]
          for k in range(n)]
    christoffel_ring = {(i, j, k): (dM[k][i][j] + dM[j][i][k] - dM[i][j][k]) * half
                        for i in range(n) for j in range(n) for k in range(j, n)}
    C = [[sum((christoffel_ring[i, min(j, k), max(j, k)] * A.qd[k] for k in range(n)),
              A.ring.zero) for j in range(n)] for i in range(n)]
    g = [[A.derivative(P, i)] for i in range(n)]
    M_expr = A.matrix(M)
    scale = A.largest(M)  # Christoffel symbols and C: noise is noise next to M
    christoffel = tuple((key, value) for key, value in
                        ((key, A.expr(v, scale)) for key, v in christoffel_ring.items())
                        if value != 0)
    return TextbookDerivation(
        q, qd, tuple(model.gravity), tuple(bodies), quadratic_form(M_expr, qd), A.expr(P),
        M_expr, christoffel, A.matrix(C, reference=scale),
        A.matrix(g, reference=A.largest([[P]])), tuple(sorted(parallel.items())), A.written)


def description_floats(model: RobotModel) -> frozenset[float]:
    """The floats of ``model``'s description (gravity, inertials, joint axes and origins,
    actuators, parameter values): documents print these with all their digits, and round only
    floats computed from them (:func:`round_floats`)."""
    found = {float(p.value) for p in model.parameters if p.value is not None}
    for value in all_scalars(model):
        if isinstance(value, sp.Basic):
            found.update(float(f) for f in value.atoms(sp.Float))
        elif isinstance(value, float):
            found.add(value)
    return frozenset(found)


def quadratic_form(A: sp.Matrix, x) -> sp.Expr:
    """``½ xᵀ A x`` for a symmetric ``A``, as ``Σ_j ½ A_jj x_j² + Σ_{j<k} A_jk x_j x_k`` with the
    coefficients kept as they are (not expanded into the products)."""
    n = len(x)
    terms = [A[j, j] * x[j] ** 2 / 2 for j in range(n)]
    terms += [A[j, k] * x[j] * x[k] for j in range(n) for k in range(j + 1, n)]
    return sp.Add(*terms)


def christoffel_symbols(M: sp.Matrix, q) -> tuple[tuple[tuple[int, int, int], sp.Expr], ...]:
    """The non-zero Christoffel symbols of the first kind of the mass matrix ``M(q)``.

    ``c_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)`` (0-based ``i, j, k``), simplified; since
    ``c_ijk = c_ikj`` only ``j ≤ k`` is returned, in the order ``i, j, k``.

    Examples
    --------
    >>> q1, q2 = sp.symbols("q1 q2")
    >>> christoffel_symbols(sp.Matrix([[3 + 2 * sp.cos(q2), 1], [1, 1]]), (q1, q2))
    (((0, 0, 1), -sin(q2)), ((1, 0, 0), sin(q2)))
    """
    n = len(q)
    dM = [M.diff(qk) for qk in q]
    scale = largest_coefficient(sp.expand(e) for e in M)  # what is noise next to M
    out = []
    for i in range(n):
        for j in range(n):
            for k in range(j, n):
                value = simplify_trig((dM[k][i, j] + dM[j][i, k] - dM[i][j, k]) / 2, q, scale)
                if value != 0:
                    out.append(((i, j, k), value))
    return tuple(out)
