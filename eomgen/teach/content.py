"""What a handout says: :func:`build_handout` turns a robot model into a :class:`Handout`.

The sequence is the textbook's (e.g. Spong, Hutchinson & Vidyasagar, *Robot Modeling and
Control*, the planar two-link arm):

1. the robot: a kinematic sketch, the joint, link and parameter tables, gravity;
2. the method and notation (Lagrangian, Euler–Lagrange equations, ``s_1``, ``c_{12}``);
3. for teaching-sized models (see :func:`eomgen.present.notation.textbook_for`):
   positions of the centres of mass, velocities (Jacobians), kinetic energy, potential energy,
   the mass matrix (symmetric entries once, terms grouped by body mass), the Christoffel
   symbols and C (common factors named, e.g. ``h = m_2 l_1 l_{c2} s_2``), the gravity vector
   (grouped by the trigonometric functions), the complete equations of motion;
   for larger models, the straight-line program of named subexpressions instead, saying so;
4. when the joints have drives (:mod:`eomgen.actuators`): Spong's link and motor equations
   for flexible joints, or ``M + diag(a)`` and the friction torque for rigid ones, joint by
   joint (:func:`drive_equations`); when the scene has contacts: ``M q̈ + C q̇ + g = τ +
   J_cᵀ F_c``, ``J_c q̈ + J̇_c q̇ = 0`` and ``J_c`` written out (:func:`contact_equations`);
5. the verified properties, with the numbers of :func:`eomgen.verify`.

Every expression is printed by eomgen's LaTeX printer
(:class:`~eomgen.present.printer.DerivationLatexPrinter`); user text (names,
descriptions) travels as :func:`~eomgen.teach.document.code` or
:func:`~eomgen.teach.document.plain` spans and is escaped by each renderer.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Callable

import sympy as sp

from .. import __version__
from ..actuators import SpongDynamics, joint_actuators, spong_dynamics
from ..codegen.functions import module_name
from ..dynamics import Dynamics, derive
from ..errors import ParameterError
from ..model import IDENTITY3, RobotModel
from ..present import notation as nt
from ..present import readability as rd
from ..present.sections import program_sections
from ..progress import plural
from ..symbolic.textbook import TextbookDerivation
from ..verify import VerificationReport, verify
from .document import (Equation, Equations, Figure, Handout, Paragraph, Section, Span, Table,
                       code, math, plain, prose)

#: Options of the printed derivation: the LaTeX backend's, with fewer named subexpressions
#: for large models (a handout is read, not searched).
HANDOUT_CONFIG = nt.LatexConfig(max_program_lines=300)

#: States sampled by the property checks.
VERIFY_SAMPLES = 20


class _Writer:
    """Builds equations with the document's printer."""

    def __init__(self, p: nt.Printing):
        self.p = p

    def tex(self, expr) -> str:
        return self.p.tex(expr)

    def eq(self, lhs: str, expr) -> Equation:
        return self.convert([self.p.equation(lhs, expr)])[0]

    def terms(self, lhs: str, terms: list) -> Equation:
        """``lhs =`` the sum of ``terms`` in the given order."""
        lines = self.p.printer.print_sum_lines(terms or [sp.Integer(0)], self.p.width)
        return Equation(lhs, tuple(lines))

    def matrix(self, lhs: str, matrix: sp.Matrix) -> tuple[Equation, ...]:
        return self.convert(nt.matrix_equations(self.p, lhs, matrix))

    @staticmethod
    def convert(equations) -> tuple[Equation, ...]:
        """The LaTeX backend's equations as the handout's."""
        return tuple(Equation(e.lhs, tuple(e.lines)) for e in equations)


def _vector(w: _Writer, values) -> Span:
    return math(nt.vector(w.p, values))


# -- the robot ------------------------------------------------------------------------------

def _scene_paragraph(report) -> Paragraph:
    """What a scene (:mod:`eomgen.scene`) did to the description, in one paragraph."""
    parts: list = ["This handout models ", code(report.robot), " as the scene ",
                   code(Path(report.scene).name), " reduces it"]
    parts += [": ", plain(report.description)] if report.description else []
    parts.append(f". Moving: {len(report.moving)} of {report.before.dof} joints")
    if report.locked:
        parts.append("; locked (rad or m): ")
        for k, lock in enumerate(report.locked):
            parts += ([", "] if k else []) + [code(lock.name), f" = {lock.position:g}"]
    parts.append("; links rigidly attached to a moving body are merged into it.")
    return Paragraph(prose(*parts))


def _robot_section(model: RobotModel, w: _Writer, sketch_caption: tuple,
                   scene=None) -> Section:
    blocks: list = []
    info = dict(model.info)
    if info.get("description"):
        blocks.append(Paragraph((plain(str(info["description"])),)))
    if scene is not None:
        blocks.append(_scene_paragraph(scene))
    movable = {j.name: k for k, j in enumerate(model.movable_joints, start=1)}
    blocks.append(Paragraph(prose(
        code(model.name), f" has {model.dof} movable joint{'s' if model.dof != 1 else ''}; "
        "the gravitational acceleration in its base frame is ",
        math(r"g_{\mathrm{vec}} = " + nt.vector(w.p, model.gravity)),
        " (m/s$^{2}$). Figure 1 sketches the robot; the tables list what the description "
        "gives.")))
    blocks.append(Figure("sketch", sketch_caption))
    rows = []
    for joint in model.joints:
        if joint.origin.rotation == IDENTITY3:
            rpy = prose("$0$")
        else:
            angles = nt.rpy(joint.origin.rotation)
            rpy = (_vector(w, angles),) if angles is not None else prose("symbolic")
        rows.append((
            prose(f"$q_{{{movable[joint.name]}}}$") if joint.name in movable else (),
            (code(joint.name),), (plain(joint.type.value),),
            (code(joint.parent),), (code(joint.child),),
            (_vector(w, joint.axis),) if joint.type.is_movable else (),
            (_vector(w, joint.origin.translation),), rpy))
    blocks.append(Paragraph(prose(
        "Joints, in the order of the joint vector $q$. A joint's origin is the pose of its "
        "frame in the parent link's frame (translation in m; roll, pitch, yaw in rad); the "
        "child link's frame is the joint frame turned about (revolute) or moved along "
        "(prismatic) the joint axis, given in the joint frame.")))
    blocks.append(Table(tuple(prose(h) for h in (
        "variable", "joint", "type", "parent", "child", "axis", "origin xyz", "origin rpy")),
        tuple(rows), small=True))
    if "dh" in info:
        columns = list(info.get("dh_columns", ("joint", "type", "a", "alpha", "d", "theta")))
        dh_rows = [tuple((math(w.tex(v)),) if isinstance(v, sp.Basic) else (code(str(v)),)
                         for v in row) for row in info["dh"]]
        blocks.append(Paragraph(prose(
            "Denavit–Hartenberg table (", plain(str(info.get("convention", ""))),
            " convention); the joint variable is added to $\\theta$ (revolute) or $d$ "
            "(prismatic).")))
        blocks.append(Table(tuple(prose(nt.DH_HEADINGS.get(c, c)) for c in columns),
                            tuple(dh_rows),
                            small=True))
    link_rows = []
    for link in model.links:
        if link.inertial is None:
            link_rows.append(((code(link.name),), prose("massless"), (), ()))
            continue
        I = link.inertial.inertia
        link_rows.append(((code(link.name),), (math(w.tex(link.inertial.mass)),),
                          (_vector(w, link.inertial.com),),
                          (_vector(w, [I[0][0], I[1][1], I[2][2], I[0][1], I[0][2], I[1][2]]),)))
    blocks.append(Paragraph(prose(
        "Links: mass (kg), centre of mass in the link frame (m) and rotational inertia about "
        "the centre of mass in link axes, $(I_{xx}, I_{yy}, I_{zz}, I_{xy}, I_{xz}, I_{yz})$ "
        "(kg m$^{2}$).")))
    blocks.append(Table(tuple(prose(h) for h in ("link", "mass", "centre of mass", "inertia")),
                        tuple(link_rows), small=True))
    if model.parameters:
        par_rows = tuple(
            ((math(w.tex(par.symbol)),),
             (math(w.tex(sp.Float(par.value, 15))),) if par.value is not None else prose("none"),
             (plain(par.description),))
            for par in sorted(model.parameters, key=lambda par: par.name))
        blocks.append(Paragraph(prose(
            "Parameters: symbols kept in the equations, with the values the description "
            "gives them (used by the sketch and the numeric checks).")))
        blocks.append(Table(tuple(prose(h) for h in ("symbol", "value", "meaning")), par_rows))
    return Section("The robot", tuple(blocks))


def _method_section(model: RobotModel, teaching: bool) -> Section:
    n = model.dof
    q = ("(" + ", ".join(f"q_{{{k}}}" for k in range(1, n + 1)) + ")" if n <= 3
         else f"(q_{{1}}, \\dots, q_{{{n}}})")
    blocks = [
        Paragraph(prose(
            f"The joint positions $q = {q}$ (rad for revolute joints, m for prismatic ones) "
            "are the generalised coordinates. With the kinetic energy $K(q, \\dot{q})$ and the "
            "potential energy $P(q)$ of the whole robot, the Lagrangian is $L = K - P$ and the "
            "Euler–Lagrange equations give the joint efforts $\\tau$ (N m or N):")),
        Equations((Equation(r"\frac{d}{dt} \frac{\partial L}{\partial \dot{q}_{i}} "
                            r"- \frac{\partial L}{\partial q_{i}}", (r"\tau_{i},",)),)),
        Paragraph(prose(
            "Because the kinetic energy is a quadratic form of the velocities, "
            "$K = \\tfrac{1}{2} \\dot{q}^{T} M(q) \\dot{q}$, these equations take the form")),
        Equations((Equation(r"M(q)\, \ddot{q} + C(q, \dot{q})\, \dot{q} + g(q)", (r"\tau",)),)),
        Paragraph(prose(
            "with the mass matrix $M$, the Coriolis matrix $C$ and the gravity vector $g$. "
            "Body $k$ is the child link of joint $k$ together with the links fixed to it; "
            "vectors and matrices are in the base frame.")),
    ]
    if teaching:
        blocks.append(Paragraph(prose(
            "Notation: $s_{1} = \\sin q_{1}$, $c_{1} = \\cos q_{1}$, "
            "$s_{12} = \\sin(q_{1} + q_{2})$, $c_{12} = \\cos(q_{1} + q_{2})$, and so on; "
            "$\\dot{q}_{k}$ and $\\ddot{q}_{k}$ are the joint velocities and accelerations.")))
    return Section("Method and notation", tuple(blocks))


# -- the textbook derivation ----------------------------------------------------------------

def _masses(book: TextbookDerivation) -> list[sp.Symbol]:
    return [b.mass for b in book.bodies if isinstance(b.mass, sp.Symbol)]


def _textbook_sections(dyn: Dynamics, book: TextbookDerivation, coriolis,
                       w: _Writer) -> list[Section]:
    model = dyn.model
    n = model.dof
    masses = _masses(book)
    angles = list(dyn.q)
    index = {b.joint: model.joint_names.index(b.joint) + 1 for b in book.bodies}

    def mass_sum(lhs, expr):
        return w.terms(lhs, rd.by_mass(expr, masses))

    def trig_sum(lhs, expr):
        return w.terms(lhs, rd.by_trig(expr, angles))

    sections = []
    positions = []
    for b in book.bodies:
        positions.append(Paragraph(prose(
            f"Body {index[b.joint]} (joint ", code(b.joint), ", links ",
            *_names(b.links), f"), mass ${w.tex(b.mass)}$:")))
        positions.append(Equations(w.matrix(f"p_{{c{index[b.joint]}}}", b.com)))
    sections.append(Section("Step 1: positions of the centres of mass", (
        Paragraph(prose(
            "Chaining the joint transforms from the base gives the position $p_{ck}(q)$ of the "
            "centre of mass of each body (m).")), *positions)))

    velocities = [Paragraph(prose(
        "Differentiating the positions gives the linear velocity of each centre of mass, "
        "$v_{ck} = J_{vk}\\, \\dot{q}$ with $J_{vk} = \\partial p_{ck} / \\partial q$; the "
        "angular velocity is $\\omega_{k} = J_{\\omega k}\\, \\dot{q}$, whose column $j$ is the "
        "axis of joint $j$ when that joint is revolute and moves body $k$, else zero."))]
    for b in book.bodies:
        k = index[b.joint]
        velocities.append(Equations(w.matrix(f"J_{{v{k}}}", b.J_v)
                                    + w.matrix(f"J_{{\\omega {k}}}", b.J_w)))
    sections.append(Section("Step 2: velocities", tuple(velocities)))

    kinetic = [Paragraph(prose(
        "Each body contributes translation and rotation: "
        "$K_{k} = \\tfrac{1}{2} m_{k} v_{ck}^{T} v_{ck} + \\tfrac{1}{2} \\omega_{k}^{T} R_{k} "
        "I_{ck} R_{k}^{T} \\omega_{k}$, with $R_{k}$ the rotation of body $k$ and $I_{ck}$ its "
        "inertia about its centre of mass in body axes (J)."))]
    for b in book.bodies:
        k = index[b.joint]
        kinetic.append(Equations(w.matrix(f"R_{{{k}}}", b.rotation)
                                 + w.matrix(f"I_{{c{k}}}", b.inertia)
                                 + (w.terms(f"K_{{{k}}}", _quadratic_terms(b.M, dyn.qd, masses)),)))
    kinetic.append(Paragraph(prose("The total kinetic energy, $K = \\sum_{k} K_{k}$:")))
    kinetic.append(Equations((w.terms("K", _quadratic_terms(book.M, dyn.qd, masses)),)))
    sections.append(Section("Step 3: kinetic energy", tuple(kinetic)))

    potential = [Paragraph(prose(
        "The potential energy of body $k$ in the uniform gravity field is "
        "$P_{k} = -m_{k}\\, g_{\\mathrm{vec}}^{T} p_{ck}$ (J):")),
        Equations(tuple(trig_sum(f"P_{{{index[b.joint]}}}", b.P) for b in book.bodies)),
        Paragraph(prose("and the total, $P = \\sum_{k} P_{k}$:")),
        Equations((trig_sum("P", book.P),))]
    sections.append(Section("Step 4: potential energy", tuple(potential)))

    M_eqs = tuple(mass_sum(f"M_{{{i + 1},{j + 1}}}", book.M[i, j])
                  for i in range(n) for j in range(i, n))
    sections.append(Section("Step 5: the mass matrix", (
        Paragraph(prose(
            "The kinetic energy is $K = \\tfrac{1}{2} \\dot{q}^{T} M(q)\\, \\dot{q}$ with "
            "$M = \\sum_{k} m_{k} J_{vk}^{T} J_{vk} + J_{\\omega k}^{T} R_{k} I_{ck} R_{k}^{T} "
            "J_{\\omega k}$: the coefficient of $\\dot{q}_{i} \\dot{q}_{j}$ in $K$ is "
            "$M_{i,j}$ ($i < j$), and that of $\\dot{q}_{i}^{2}$ is $\\tfrac{1}{2} M_{i,i}$. "
            "$M$ is symmetric, so only $M_{i,j}$ with $i \\le j$ are shown "
            "($M_{j,i} = M_{i,j}$).")),
        Equations(M_eqs))))

    sections.append(_coriolis_section(book, coriolis, w))

    sections.append(Section("Step 7: the gravity vector", (
        Paragraph(prose("$g_{i} = \\partial P / \\partial q_{i}$ (N m or N):")),
        Equations(tuple(trig_sum(f"g_{{{i + 1}}}", book.g[i]) for i in range(n))))))

    sections.append(_equations_section(dyn, book, coriolis, w))
    return sections


def _names(names) -> list:
    out: list = []
    for k, name in enumerate(names):
        out += ([", "] if k else []) + [code(name)]
    return out


#: The factor ½ of the kinetic energy, printed as ``\tfrac{1}{2}`` in front of its term.
HALF = sp.Symbol("eomgen_one_half", positive=True)


_mass_grouped = rd.mass_grouped


def _quadratic_terms(M: sp.Matrix, qd, masses) -> list[sp.Expr]:
    """``½ q̇ᵀ M q̇`` as the terms ``½ M_jj q̇_j²`` and ``M_jk q̇_j q̇_k`` (j < k), each entry
    grouped by mass (``HALF`` stands for ½: ``.subs(HALF, 1/2)`` computes with them)."""
    n = len(qd)
    terms = []
    for j in range(n):
        for k in range(j, n):
            if M[j, k] == 0:
                continue
            inner = _mass_grouped(M[j, k], masses)
            velocity = qd[j] ** 2 if j == k else qd[j] * qd[k]
            if inner.is_Number:  # a number takes the ½ in: 0.133 q̇_1², not ½ · 0.266 q̇_1²
                terms.append((inner / 2 if j == k else inner) * velocity)
                continue
            factors = [HALF] if j == k else []
            terms.append(sp.Mul(*factors, inner, velocity, evaluate=False))
    return terms


def named_coriolis(dyn: Dynamics, book: TextbookDerivation):
    """The names of the common factors of the Christoffel symbols (see
    :func:`~eomgen.teach.readability.common_christoffel_factors`; none when a parameter is
    already called ``h``…), the Christoffel symbols written with them, and C written with them
    (checked equal to the derived C)."""
    n = dyn.model.dof
    taken = {p.name for p in dyn.model.parameters}
    names = [] if taken & {"h", "h1", "h2", "h3", "h4"} else rd.common_christoffel_factors(
        [value for _, value in book.christoffel])
    christoffel = [(key, rd.in_terms_of(value, names)) for key, value in book.christoffel]
    C = sp.zeros(n, n)
    for (i, j, k), value in christoffel:
        C[i, j] += value * dyn.qd[k]
        if j != k:
            C[i, k] += value * dyn.qd[j]
    C = C.applyfunc(sp.factor_terms)
    values = {nf.symbol: nf.value for nf in names}
    if (C.subs(values) - book.C).applyfunc(sp.expand) != sp.zeros(n, n):
        raise AssertionError("C written with named factors differs from the derived C")
    return names, christoffel, C


def _coriolis_section(book: TextbookDerivation, coriolis, w: _Writer) -> Section:
    names, christoffel, C = coriolis
    blocks = [Paragraph(prose(
        "The Christoffel symbols of the first kind are "
        "$\\Gamma_{i,j,k} = \\tfrac{1}{2} \\bigl(\\partial M_{i,j} / \\partial q_{k} + "
        "\\partial M_{i,k} / \\partial q_{j} - \\partial M_{j,k} / \\partial q_{i}\\bigr)$, "
        "symmetric in $j, k$ (so each is shown once); those not listed are zero."))]
    if names:
        blocks.append(Paragraph(prose(
            "They are all multiples of " + ("one expression" if len(names) == 1 else
                                              f"{len(names)} expressions") + ", named:")))
        masses = _masses(book)
        blocks.append(Equations(tuple(w.terms(w.tex(nf.symbol), rd.by_mass(nf.value, masses))
                                      for nf in names)))
    equations = []
    for (i, j, k), value in christoffel:
        lhs = rf"\Gamma_{{{i + 1},{j + 1},{k + 1}}}"
        if j != k:
            lhs += rf" = \Gamma_{{{i + 1},{k + 1},{j + 1}}}"
        equations.append(w.eq(lhs, value))
    blocks.append(Equations(tuple(equations)) if equations else
                  Paragraph(prose("All Christoffel symbols are zero.")))
    blocks.append(Paragraph(prose(
        "The Coriolis matrix is $C_{i,j} = \\sum_{k} \\Gamma_{i,j,k}\\, \\dot{q}_{k}$ "
        "(with this choice, $\\dot{M} - 2C$ is skew-symmetric):")))
    blocks.append(Equations(w.matrix("C", C)))
    return Section("Step 6: Christoffel symbols and the Coriolis matrix", tuple(blocks))


def _compact_terms(dyn: Dynamics, book: TextbookDerivation | None, coriolis, i: int):
    """Row ``i`` of ``M q̈ + C q̇ + g`` as a student writes it with the entries' names: the
    terms ``M_{i,j} q̈_j``, the velocity terms and ``g_i`` (three lists). With the textbook
    derivation (``book`` and ``coriolis``) the velocity terms are those of step 6, grouped by
    its named factors and zero entries are left out; without it (large models) they are
    ``C_{i,j} q̇_j``. The names are the symbols ``M<i>_<j>`` (``i ≤ j``), ``C<i>_<j>``,
    ``g<i>`` (see :func:`abbreviation_values`)."""
    n = dyn.model.dof
    qd, qdd = dyn.qd, dyn.qdd
    M = book.M if book is not None else None
    entry = [sp.Symbol(f"M{min(i, j) + 1}_{max(i, j) + 1}") * qdd[j]
             for j in range(n) if M is None or M[i, j] != 0]
    if book is None:
        velocity = [sp.Symbol(f"C{i + 1}_{j + 1}") * qd[j] for j in range(n)]
        return entry, velocity, [sp.Symbol(f"g{i + 1}")]
    names, _, C = coriolis
    symbols = [nf.symbol for nf in names]
    Cqd = sp.expand(sum((C[i, j] * qd[j] for j in range(n)), sp.Integer(0)))
    velocity = rd.group_by_factor(Cqd, lambda t: next((h for h in symbols if t.has(h)), None))
    return entry, velocity, ([sp.Symbol(f"g{i + 1}")] if book.g[i] != 0 else [])


def abbreviation_values(dyn: Dynamics, coriolis=None) -> dict[sp.Symbol, sp.Expr]:
    """What the names of :func:`_compact_terms` stand for: ``M<i>_<j>``, ``C<i>_<j>``,
    ``g<i>`` of ``dyn`` and the named Christoffel factors of ``coriolis`` (for checks:
    ``expr.subs(values)`` is in joint variables and parameters only)."""
    n = dyn.model.dof
    values: dict[sp.Symbol, sp.Expr] = {}
    for i in range(n):
        values[sp.Symbol(f"g{i + 1}")] = dyn.g[i]
        for j in range(n):
            values[sp.Symbol(f"C{i + 1}_{j + 1}")] = dyn.C[i, j]
            if i <= j:
                values[sp.Symbol(f"M{i + 1}_{j + 1}")] = dyn.M[i, j]
    if coriolis is not None:
        values.update({nf.symbol: nf.value for nf in coriolis[0]})
    return values


def _equations_section(dyn: Dynamics, book: TextbookDerivation, coriolis,
                       w: _Writer) -> Section:
    n = dyn.model.dof
    names = coriolis[0]
    masses = _masses(book)
    qdd = dyn.qdd
    compact, full = [], []
    for i in range(n):
        entry, velocity_terms, gi = _compact_terms(dyn, book, coriolis, i)
        compact.append(w.terms(rf"\tau_{{{i + 1}}}", entry + velocity_terms + gi))
        written = []
        for j in range(n):
            if book.M[i, j] != 0:
                written.append(sp.Mul(_mass_grouped(book.M[i, j], masses), qdd[j],
                                      evaluate=False))
        written += velocity_terms + rd.by_trig(book.g[i], list(dyn.q))
        full.append(w.terms(rf"\tau_{{{i + 1}}}", written))
    blocks = [Paragraph(prose(
        "Putting the pieces together, $M(q)\\, \\ddot{q} + C(q, \\dot{q})\\, \\dot{q} + "
        "g(q) = \\tau$ reads, joint by joint, with the entries above:")),
        Equations(tuple(compact)),
        Paragraph(prose("and written out in full:")),
        Equations(tuple(full))]
    if names:
        blocks.append(Paragraph(prose(
            "where " + ", ".join(f"${w.tex(nf.symbol)}$" for nf in names)
            + (" is" if len(names) == 1 else " are") + " as in step 6.")))
    return Section("Step 8: the equations of motion", tuple(blocks))


# -- drives: armature, friction, flexible joints --------------------------------------------

def has_drives(model: RobotModel) -> bool:
    """Whether any joint's actuator adds to the rigid-body equations (armature, friction or
    a stiffness): the handout then gets :func:`_drives_section`."""
    return any(a.flexible or a.armature != 0 or a.damping != 0 or a.friction != 0
               for a in joint_actuators(model))


def _spring(k: int) -> sp.Symbol:
    """Stands for the spring torque ``K_k (θ_k − q_k)`` of flexible joint ``k`` (0-based) in the
    printed equations, so that it prints in this order (:func:`spring_values` gives its value)."""
    return sp.Symbol(f"eomgen_spring_{k + 1}", real=True)


def spring_values(spong: SpongDynamics) -> dict[sp.Symbol, sp.Expr]:
    """The value ``K_k (θ_k − q_k)`` of each :func:`_spring` placeholder."""
    q = spong.dynamics.q
    return {_spring(k): spong.actuators[k].stiffness * (th - q[k])
            for k, th in zip(spong.flexible, spong.theta)}


def drive_symbol_names(spong: SpongDynamics, tex: Callable[[sp.Expr], str]
                       ) -> dict[sp.Symbol, str]:
    """LaTeX of the motor states ``θ_k``, ``θ̇_k``, ``θ̈_k``, of the inputs (``τ_{m,k}``, the motor
    torque, for a flexible joint ``k``; ``τ_k`` for a rigid one) and of the spring torques
    (``tex`` prints the stiffness)."""
    names: dict[sp.Symbol, str] = {}
    q = spong.dynamics.q
    for k, th, thd, thdd in zip(spong.flexible, spong.theta, spong.thetad, spong.thetadd):
        names[th] = rf"\theta_{{{k + 1}}}"
        names[thd] = rf"\dot{{\theta}}_{{{k + 1}}}"
        names[thdd] = rf"\ddot{{\theta}}_{{{k + 1}}}"
        stiffness = spong.actuators[k].stiffness
        factor = tex(stiffness)
        if not (stiffness.is_Symbol or stiffness.is_Number):
            factor = r"\left(" + factor + r"\right)"
        names[_spring(k)] = (factor + r" \left(" + names[th] + " - " + tex(q[k]) + r"\right)")
    for k, tau in enumerate(spong.tau):
        names[tau] = rf"\tau_{{m,{k + 1}}}" if k in spong.flexible else rf"\tau_{{{k + 1}}}"
    return names


def _friction_terms(actuator, velocity) -> list[sp.Expr]:
    """``d v`` and ``f sign(v)`` (those that are not zero)."""
    terms = [actuator.damping * velocity] if actuator.damping != 0 else []
    return terms + ([actuator.friction * sp.sign(velocity)] if actuator.friction != 0 else [])


def drive_equations(spong: SpongDynamics, book: TextbookDerivation | None, coriolis):
    """The equations of Spong's model (every joint rigid when none has a stiffness: then the
    rigid equations with armature and friction) joint by joint, as the handout prints them.

    Returns
    -------
    links, motors:
        Lists of ``(lhs, terms)``: ``lhs = Σ terms``. A link equation has the input on the
        left, ``K_k (θ_k − q_k)`` for a flexible joint and ``τ_k`` for a rigid one, and on the
        right the row of ``M q̈ + C q̇ + g`` in the names of :func:`_compact_terms`, plus
        ``a_k q̈_k`` and the friction of a rigid joint (the spring torque is the placeholder
        :func:`_spring`). A motor equation reads
        ``τ_{m,k} = B_k θ̈_k + K_k (θ_k − q_k) + τ_f,k(θ̇_k)``. With
        :func:`abbreviation_values` and :func:`spring_values` substituted, ``terms − lhs``
        are the residuals of
        :meth:`~eomgen.actuators.SpongDynamics.link_equations` and
        :meth:`~eomgen.actuators.SpongDynamics.motor_equations` (exact friction).
    """
    dyn = spong.dynamics
    links, motors = [], []
    for k, a in enumerate(spong.actuators):
        entry, velocity, gk = _compact_terms(dyn, book, coriolis, k)
        if k in spong.flexible:
            column = spong.flexible.index(k)
            links.append((_spring(k), entry + velocity + gk))
            motors.append((spong.tau[k], [a.armature * spong.thetadd[column], _spring(k)]
                           + _friction_terms(a, spong.thetad[column])))
        else:
            armature = [a.armature * dyn.qdd[k]] if a.armature != 0 else []
            links.append((spong.tau[k], entry + armature + velocity + gk
                          + _friction_terms(a, dyn.qd[k])))
    return links, motors


def _drives_section(spong: SpongDynamics, book: TextbookDerivation | None, coriolis,
                    w: _Writer) -> Section:
    model = spong.dynamics.model
    links, motors = drive_equations(spong, book, coriolis)
    names = [j.name for j in model.movable_joints]
    friction = any(a.damping != 0 or a.friction != 0 for a in spong.actuators)
    entries = ("the entries of steps 5 to 7" if book is not None else
               "the entries $M_{i,j}$, $C_{i,j}$ and $g_{i}$ of the program above")
    friction_text = (
        " Friction takes the torque $d\\, v + f \\operatorname{sign}(v)$ from a drive turning "
        "at the rate $v$ (viscous coefficient $d$ in N m s/rad, Coulomb torque $f$ in N m)"
        + ("; it acts on the motor of a flexible joint and on the joint of a rigid one."
           if spong.flexible else ".") if friction else "")
    blocks: list = []
    if spong.flexible:
        flexible = [names[k] for k in spong.flexible]
        stiffness = [spong.actuators[k].stiffness for k in spong.flexible]
        inertia = [spong.actuators[k].armature for k in spong.flexible]
        blocks.append(Paragraph(prose(
            "The description makes " + ("joints " if len(flexible) > 1 else "joint "),
            *_names(flexible), f" flexible: an elastic transmission (a spring, stiffness in "
            "N m/rad) sits between the joint and its motor. The motor angle $\\theta_{i}$ "
            "(rad, on the link side of the gear: the rotor angle divided by the gear ratio) "
            "becomes a state of its own beside the link angle $q_{i}$, and the spring passes "
            "its stiffness times $\\theta_{i} - q_{i}$ from the motor to the link. This is "
            "Spong's reduced model: it assumes that the kinetic energy of each motor comes only "
            "from its own spin, one half its motor inertia (the rotor inertia reflected through "
            "the gear, kg m$^{2}$) times $\\dot{\\theta}_{i}^{2}$; the part of the rotor's "
            "angular velocity due to the links that carry it is neglected (the rotor's mass "
            "belongs to the link that carries it)." + friction_text)))
        rows = tuple(((code(names[k]),), prose(f"$q_{{{k + 1}}}$"),
                      (math(w.tex(spong.theta[c])),), (math(w.tex(stiffness[c])),),
                      (math(w.tex(inertia[c])),))
                     for c, k in enumerate(spong.flexible))
        blocks.append(Table(tuple(prose(h) for h in (
            "joint", "link angle", "motor angle", "stiffness", "motor inertia")), rows))
        rigid_note = ("" if not spong.rigid else
                      "; the rows of a rigid joint have its joint torque $\\tau_{i}$ on the "
                      "right (and its armature adds to $M$)")
        blocks.append(Paragraph(prose(
            "The Euler–Lagrange equations of the links and of the motors, the link equations "
            "and the motor equations, are")))
        blocks.append(Equations((
            Equation(r"M(q)\, \ddot{q} + C(q, \dot{q})\, \dot{q} + g(q)",
                     (r"K (\theta - q),",)),
            Equation(r"B\, \ddot{\theta} + K (\theta - q)", (r"\tau_{m},",)))))
        blocks.append(Paragraph(prose(
            "with the stiffness matrix $K = \\operatorname{diag}"
            + nt.vector(w.p, stiffness) + "$ (not the kinetic energy of step 3), the motor "
            "inertia matrix $B = \\operatorname{diag}" + nt.vector(w.p, inertia) + "$, the "
            "motor angles $\\theta = " + nt.vector(w.p, spong.theta) + "$ and the motor "
            "torques $\\tau_{m}$" + rigid_note + ". Joint by joint, with " + entries
            + ", the link equations read")))
        blocks.append(Equations(tuple(w.terms(w.tex(lhs), terms) for lhs, terms in links)))
        blocks.append(Paragraph(prose("and the motor equations")))
        blocks.append(Equations(tuple(w.terms(w.tex(lhs), terms) for lhs, terms in motors)))
        title = "Flexible joints"
    else:
        armature = [a.armature for a in spong.actuators]
        blocks.append(Paragraph(prose(
            "The description gives the joints' drives. A motor behind a gear of ratio $r$ adds "
            "its reflected rotor inertia, the armature $a_{i} = r_{i}^{2} I_{\\mathrm{rotor},i}$ "
            "(kg m$^{2}$), to the diagonal of the mass matrix." + friction_text
            + " The equations of motion become")))
        blocks.append(Equations((Equation(
            r"\bigl(M(q) + \operatorname{diag}(a)\bigr)\, \ddot{q} + C(q, \dot{q})\, \dot{q} "
            r"+ g(q) + \tau_{f}(\dot{q})", (r"\tau,",)),)))
        blocks.append(Paragraph(prose(
            "with $a = " + nt.vector(w.p, armature) + "$ and the friction torques "
            "$\\tau_{f} = " + nt.vector(w.p, [sp.Add(*_friction_terms(a, v)) for a, v in
                                              zip(spong.actuators, spong.dynamics.qd)])
            + "$. Joint by joint, with " + entries + ":")))
        blocks.append(Equations(tuple(w.terms(w.tex(lhs), terms) for lhs, terms in links)))
        title = "Drives: armature and friction"
    blocks.append(Paragraph(prose(
        "The properties verified below are those of the rigid-body terms $M$, $C$ and "
        "$g$.")))
    return Section(title, tuple(blocks))


# -- contacts -----------------------------------------------------------------------------

_FORCE_AXES = ("f_x", "f_y", "f_z", "n_x", "n_y", "n_z")


def contact_forces(contacts) -> list[sp.Symbol]:
    """The symbols of ``F_c``, in the order of the rows of ``J_c``: ``f_x, f_y, f_z`` per
    point contact, ``f_x … n_z`` per surface contact (``eomgen_<axis>_<k>``, k 1-based)."""
    return [sp.Symbol(f"eomgen_{axis}_{k}", real=True)
            for k, c in enumerate(contacts, start=1) for axis in _FORCE_AXES[:c.size]]


def contact_symbol_names(contacts) -> dict[sp.Symbol, str]:
    """LaTeX of :func:`contact_forces`: ``f_{x}`` for one contact, ``f_{2,x}`` for several."""
    names = {}
    for symbol in contact_forces(contacts):
        _, letter, axis, k = symbol.name.split("_")
        names[symbol] = f"{letter}_{{{axis}}}" if len(contacts) == 1 else \
            f"{letter}_{{{k},{axis}}}"
    return names


def contact_equations(dyn: Dynamics, contacts, book: TextbookDerivation | None, coriolis):
    """The contact Jacobian ``J_c`` (m×n), ``J̇_c q̇`` (m×1), the forces ``F_c`` and the rows
    ``τ_i = (M q̈ + C q̇ + g)_i − (J_cᵀ F_c)_i`` as ``(lhs, terms)`` (names of
    :func:`_compact_terms`), the contact terms grouped by force component. ``J_c`` and
    ``J̇_c q̇`` are the point contacts' linear rows of the world-aligned frame Jacobian and the
    surface contacts' body Jacobian (:func:`eomgen.symbolic.frames.derive_frames`), written out
    in the joint variables in the textbook form (small models only)."""
    from ..contacts import POINT
    from ..symbolic.frames import derive_frames
    from ..symbolic.textbook import simplify_trig

    model = dyn.model
    fk = derive_frames(model, list(dict.fromkeys(c.frame for c in contacts)))
    full = fk.program.expanded()
    rows, bias = [], []
    for c in contacts:
        kinds = ("J", "dJqd") if c.kind == POINT else ("Jb", "dJbqd")
        J, b = (fk.program.expand(fk.output(kind, c.frame), full) for kind in kinds)
        rows += [J[r, :] for r in range(c.size)]
        bias += [b[r] for r in range(c.size)]
    # fk's joint symbols are dyn's (same names and assumptions)
    Jc = sp.Matrix.vstack(*rows).applyfunc(lambda e: simplify_trig(e, fk.q))
    dJqd = sp.Matrix(bias).applyfunc(lambda e: simplify_trig(e, fk.q))
    F = contact_forces(contacts)
    equations = []
    for i in range(model.dof):
        entry, velocity, gi = _compact_terms(dyn, book, coriolis, i)
        force = [-(F[r] * Jc[r, i]) for r in range(len(F)) if Jc[r, i] != 0]
        equations.append((sp.Symbol(f"tau{i + 1}", real=True), entry + velocity + gi + force))
    return Jc, dJqd, F, equations


def _contact_section(dyn: Dynamics, contacts, book: TextbookDerivation | None, coriolis,
                     w: _Writer) -> Section:
    from ..contacts import POINT

    described = []
    for k, c in enumerate(contacts):
        described += ([", "] if k else []) + [code(c.frame)]
        if c.kind == POINT:
            normal = nt.vector(w.p, [sp.Float(v, 15) for v in c.normal])
            described.append(" (a point: its origin is held still; force in world axes, N; "
                             f"normal ${normal}$)")
        else:
            described.append(" (a surface: the frame is held still; force and moment in the "
                             "frame's axes, N and N m)")
    blocks: list = [
        Paragraph(prose(
            "The scene holds ", *described, ". The contact force $F_{c}$ acts on the robot "
            "at the contact frame and enters the equations of motion through the contact "
            "Jacobian $J_{c}$ (the rows of the frame's Jacobian that the contact holds, "
            "$\\dot{p} = J_{c} \\dot{q}$ for a point), and the contact adds the constraint "
            "that the frame does not accelerate:")),
        Equations((
            Equation(r"M(q)\, \ddot{q} + C(q, \dot{q})\, \dot{q} + g(q)",
                     (r"\tau + J_{c}^{T} F_{c},",)),
            Equation(r"J_{c}(q)\, \ddot{q} + \dot{J}_{c}\, \dot{q}", (r"0.",)))),
    ]
    if book is None:
        blocks.append(Paragraph(prose(
            "For a robot of this size $J_{c}$ and $\\dot{J}_{c} \\dot{q}$ are not written out "
            "here; eomgen derives them as a program of named subexpressions "
            "(eomgen.symbolic.frames.derive_frames) and evaluates them numerically "
            "(eomgen.contacts).")))
        return Section("Contact", tuple(blocks))
    Jc, dJqd, F, equations = contact_equations(dyn, contacts, book, coriolis)
    angles = list(dyn.q)
    blocks.append(Paragraph(prose(
        "Here $F_{c} = " + nt.vector(w.p, F) + "$ and, differentiating the position of the "
        "contact frame (rows: the held directions; columns: the joints),")))
    blocks.append(Equations(w.matrix("J_{c}", Jc)))
    blocks.append(Paragraph(prose(
        "$\\dot{J}_{c} \\dot{q}$ is the acceleration of the contact frame at "
        "$\\ddot{q} = 0$:")))
    blocks.append(Equations(tuple(
        w.terms(rf"(\dot{{J}}_{{c}} \dot{{q}})_{{{r + 1}}}", rd.by_trig(dJqd[r], angles))
        for r in range(len(F)))))
    zero = [r for r in range(len(F)) if all(v == 0 for v in Jc[r, :])]
    if zero:
        blocks.append(Paragraph(prose(
            "Row" + ("s " if len(zero) > 1 else " ")
            + ", ".join(str(r + 1) for r in zero) + " of $J_{c}$ "
            + ("are" if len(zero) > 1 else "is") + " zero: no joint moves the frame in that "
            "direction, so the constraint holds by itself there and the force "
            + ", ".join(f"${w.tex(F[r])}$" for r in zero) + " is not determined by the "
            "motion (it does no work).")))
    blocks.append(Paragraph(prose(
        "Joint by joint, the torques that produce a motion $q(t)$ that keeps the contact, "
        "with the force $F_{c}$ the contact exerts, are $\\tau = M \\ddot{q} + C \\dot{q} + g - "
        "J_{c}^{T} F_{c}$ (entries as in step 8):")))
    blocks.append(Equations(tuple(w.terms(w.tex(lhs), terms) for lhs, terms in equations)))
    return Section("Contact", tuple(blocks))


# -- large models ---------------------------------------------------------------------------

def _program_section(dyn: Dynamics, w: _Writer) -> Section:
    context = program_sections(dyn, HANDOUT_CONFIG, w.p)
    ops = dyn.operation_count(["M", "C", "g"])
    c = HANDOUT_CONFIG
    blocks = [Paragraph(prose(
        f"This robot has {dyn.model.dof} joints, and the program that computes $M$, $C$ and "
        f"$g$ has {ops} arithmetic operations. Written out as expanded expressions in the "
        "joint angles these would fill many pages (the step-by-step textbook derivation is "
        f"printed for models of at most {c.textbook_max_dof} joints whose program has at "
        f"most {c.textbook_max_operations} operations). This handout therefore switches to "
        "named subexpressions: every quantity is defined once, under a name, from the joint "
        "positions, the parameters and the names defined before it, in the order eomgen "
        "computes them (the kinematics of each body, composite-body inertias, then the "
        "entries of $M$ and $g$). The equations at the end are exact in terms of these "
        "names."))]
    if context["legend"]:
        blocks.append(Paragraph(prose("Families of names:")))
        blocks.append(Table((prose("example"), prose("meaning")), tuple(
            ((math(tex),), prose(meaning)) for tex, meaning in context["legend"])))
    if context["omitted"]:
        blocks.append(Paragraph(prose(
            f"The program has {context['total']} named subexpressions; those needed only by "
            f"the {' and '.join(context['omitted'])} are not printed here (`eomgen generate "
            "--backend latex` prints them, and the generated code has them all).")))
    for group in context["groups"]:
        blocks.append(Paragraph(prose(f"{group['title']} ({group['count']}):")))
        for block in group["blocks"]:
            blocks.append(Equations(w.convert(block.equations)))
    for key, title in (("M", "Mass matrix, upper triangle ($M_{j,i} = M_{i,j}$):"),
                       ("g", "Gravity vector:"), ("C", "Coriolis matrix:")):
        if context["outputs"][key]:
            blocks.append(Paragraph(prose(title)))
            for block in context["outputs"][key]:
                blocks.append(Equations(w.convert(block.equations)))
    blocks.append(Paragraph(prose("The equations of motion, joint by joint:")))
    for block in context["equations"]:
        blocks.append(Equations(w.convert(block.equations)))
    return Section("The derivation as named subexpressions", tuple(blocks))


# -- verification ---------------------------------------------------------------------------

def _verification_section(dyn: Dynamics, report: VerificationReport | None,
                          missing: str | None) -> Section:
    if report is None:
        return Section("Verified properties", (Paragraph(prose(
            "Not checked numerically: ", plain(missing or ""), ". Give every parameter a "
            "value in the description to check the derivation.")),))
    rows = []
    for c in report.checks:
        if c.name == "M positive definite":
            result = prose(f"$\\lambda_{{\\min}} / \\lambda_{{\\max}} \\ge$ {c.max_rel_error:.2g}")
        elif c.how == "exact":
            result = prose("identically zero")
        else:
            result = prose(f"{c.max_abs_error:.1e} (relative {c.max_rel_error:.1e})")
        name = prose(_CHECK_NAMES[c.name]) if c.name in _CHECK_NAMES else (plain(c.name),)
        how = "symbolic" if c.how == "exact" else c.how.split(";")[0]
        rows.append((name, (plain(how),), result, prose("passed" if c.passed else "FAILED")))
    return Section("Verified properties", (
        Paragraph(prose(
            "eomgen checked what it derived (parameters at the values of the table above): "
            "$M$ is symmetric and positive definite, $\\dot{M} - 2C$ is skew-symmetric "
            "(the energy balance $\\dot{K} = \\dot{q}^{T} (\\tau - g)$ depends on it), and "
            "$g$, every column of $M$ and the whole equation agree with an independent "
            "numeric recursive Newton–Euler computation (RNEA) at random states "
            "($|q_{i}| \\le \\pi$, velocities and accelerations of order one).")),
        Table(tuple(prose(h) for h in ("property", "checked", "largest error", "")),
              tuple(rows)),
        Paragraph(prose(
            "All checks passed." if report.passed else
            "SOME CHECKS FAILED: these equations must not be trusted; please report it.")),
    ))


#: The checks of :func:`eomgen.verify` as the handout names them (``$…$`` is math).
_CHECK_NAMES = {
    "M symmetric": "$M$ symmetric",
    "M positive definite": "$M$ positive definite",
    "Mdot - 2C skew-symmetric": "$\\dot{M} - 2C$ skew-symmetric",
    "g = RNEA(q,0,0)": "$g(q) = \\mathrm{RNEA}(q, 0, 0)$",
    "M columns = RNEA(q,0,e_i) - RNEA(q,0,0)":
        "$M e_{i} = \\mathrm{RNEA}(q, 0, e_{i}) - \\mathrm{RNEA}(q, 0, 0)$",
    "M qdd + C qd + g = RNEA(q,qd,qdd)":
        "$M \\ddot{q} + C \\dot{q} + g = \\mathrm{RNEA}(q, \\dot{q}, \\ddot{q})$",
}


# -- the handout ----------------------------------------------------------------------------

def build_handout(model: RobotModel, progress: Callable[[str], None] = lambda message: None,
                  check: bool = True, scene=None) -> Handout:
    """The handout deriving ``model``'s equations of motion (see the module docstring).

    ``progress`` receives one line per stage (deriving, checking…); ``check=False`` leaves out
    the numeric verification (the section then says so); ``scene`` is the
    :class:`~eomgen.reduction.ReductionReport` when ``model`` comes from a scene (a paragraph
    says what was locked, and its contacts get a section).

    >>> import eomgen
    >>> handout = build_handout(eomgen.load(eomgen.example_path("planar_2link")), check=False)
    >>> [s.title for s in handout.sections][:4]
    ['The robot', 'Method and notation', 'Step 1: positions of the centres of mass', 'Step 2: velocities']
    """
    from .sketch import render_sketch, sketch_geometry

    progress(f"deriving the equations of motion of {model.name} ({plural(model.dof, 'joint')})")
    dyn = derive(model, outputs=("M", "C", "g"), simplify=False)
    book = nt.textbook_for(dyn, HANDOUT_CONFIG)
    extra_names = {HALF: r"\tfrac{1}{2}"}
    w = _Writer(nt.printing(dyn, HANDOUT_CONFIG, compact_trig=book is not None,
                            extra_names=extra_names))
    spong = spong_dynamics(dyn) if has_drives(model) else None
    contacts = tuple(getattr(scene, "contacts", ()) or ())
    extra_names.update(contact_symbol_names(contacts))
    if spong is not None:  # the drives' own symbols, printed by the document's printer
        extra_names.update(drive_symbol_names(spong, w.tex))
    w = _Writer(nt.printing(dyn, HANDOUT_CONFIG, compact_trig=book is not None,
                            extra_names=extra_names))
    geometry = sketch_geometry(model)
    pose = ", ".join(f"{v:.3g}" for v in geometry.q)
    caption = prose("Kinematic sketch of ", code(model.name), f" at the pose $q = ({pose})$ "
                    "(rad, m): links as grey lines, joints as circles (revolute) or squares "
                    "(prismatic), centres of mass $c_{k}$, gravity $g$.")
    if geometry.placeholder_parameters:
        caption += prose(" Drawn with 1 for the parameters without a value: ",
                         *_names(geometry.placeholder_parameters), ".")
    sections = [_robot_section(model, w, caption, scene), _method_section(model, book is not None)]
    coriolis = named_coriolis(dyn, book) if book is not None else None
    if book is not None:
        sections += _textbook_sections(dyn, book, coriolis, w)
    else:
        sections.append(_program_section(dyn, w))
    if spong is not None:
        sections.append(_drives_section(spong, book, coriolis, w))
    if contacts:
        sections.append(_contact_section(dyn, contacts, book, coriolis, w))
    report, missing = None, "the check was switched off"
    if check:
        progress("checking the derivation against Newton-Euler")
        try:
            report = verify(dyn, samples=VERIFY_SAMPLES)
        except ParameterError as exc:
            missing = str(exc)
    sections.append(_verification_section(dyn, report, missing))
    source = Path(model.source)
    digest = hashlib.sha256(source.read_bytes()).hexdigest() if source.is_file() else "0" * 64
    header = (f"Generated by eomgen {__version__} from {source.name!r} (sha256 {digest[:16]}).",
              "Do not edit by hand: regenerate with `eomgen teach`.")
    title = f"Equations of motion of {model.name}"
    stem = module_name(model.name)
    return Handout(stem, title, tuple(sections),
                   {"sketch": lambda fmt: render_sketch(model, fmt)}, header)
