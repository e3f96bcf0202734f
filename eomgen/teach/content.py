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
4. when the joints have drives (:mod:`eomgen.analysis.actuators`): Spong's link and motor equations
   for flexible joints, or ``M + diag(a)`` and the friction torque for rigid ones, joint by
   joint (:func:`drive_equations`); when the scene has contacts: ``M q̈ + C q̇ + g = τ +
   J_cᵀ F_c``, ``J_c q̈ + J̇_c q̇ = 0`` and ``J_c`` written out (:func:`contact_equations`);
   for teaching-sized arms with neither: the Slotine–Li regressor and the skew symmetry of
   ``Ṁ − 2C`` (:mod:`eomgen.teach.control`);
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

from ..common.version import __version__
from ..analysis.actuators import spong_dynamics
from ..common.output import module_name
from ..dynamics import Dynamics, derive
from ..errors import ParameterError, UnsupportedError
from ..model import IDENTITY3, RobotModel
from ..present import notation as nt
from ..present import readability as rd
from ..present.grouping import body_masses
from ..present.sections import program_sections
from ..common.progress import plural
from ..symbolic.textbook import TextbookDerivation
from ..verify import VerificationReport, verify
from .loops import loop_section, loop_symbol_names
from .quaternion import chart_method_section, velocity_names
from .control import control_section, has_control_section, slotine_li_equations
from .coriolis import (coriolis_section, coriolis_terms,  # noqa: F401  (re-exported)
                       named_coriolis)
from .contacts import (contact_equations, contact_forces,  # noqa: F401  (re-exported)
                       contact_section, contact_symbol_names)
from .document import (Equation, Equations, Figure, Handout, Paragraph, Section, Table, code,
                       described, math, plain, prose)
from .drives import (drive_equations, drive_symbol_names, drives_section,  # noqa: F401
                     has_drives, spring_values)
from .sketch import render_sketch, sketch_geometry
from .writer import (Writer, abbreviation_values, code_names,  # noqa: F401  (re-exported)
                     compact_terms, vector_span)

#: Options of the printed derivation: the LaTeX backend's, with fewer named subexpressions
#: for large models (a handout is read, not searched).
HANDOUT_CONFIG = nt.LatexConfig(max_program_lines=300)

#: States sampled by the property checks.
VERIFY_SAMPLES = 20


# -- the robot ------------------------------------------------------------------------------

def _scene_paragraph(report) -> Paragraph:
    """What a scene (:mod:`eomgen.scene`) did to the description, in one paragraph."""
    parts: list = ["This handout models ", code(report.robot), " as the scene ",
                   code(Path(report.scene).name), " reduces it"]
    parts += [": ", plain(report.description)] if report.description else []
    parts.append(f". Moving: {report.moving_described} of {report.before.dof} joints")
    if report.virtual_joints:
        parts.append(f", and the floating base's {len(report.virtual_joints)} virtual joints")
    if report.locked:
        parts.append("; locked (rad or m): ")
        for k, lock in enumerate(report.locked):
            parts += ([", "] if k else []) + [code(lock.name), f" = {lock.shown}"]
    parts.append("; links rigidly attached to a moving body are merged into it.")
    return Paragraph(prose(*parts))


def _robot_section(model: RobotModel, w: Writer, sketch_caption: tuple,
                   scene=None) -> Section:
    blocks: list = []
    info = dict(model.info)
    if info.get("description"):
        blocks.append(Paragraph(described(str(info["description"]))))
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
    variable = "v" if model.nq > model.dof else "q"
    for joint in model.joints:
        if joint.origin.rotation == IDENTITY3:
            rpy = prose("$0$")
        else:
            angles = nt.rpy(joint.origin.rotation)
            rpy = (vector_span(w, angles),) if angles is not None else prose("symbolic")
        rows.append((
            prose(f"${variable}_{{{movable[joint.name]}}}$") if joint.name in movable else (),
            (code(joint.name),), (plain(joint.type.value),),
            (code(joint.parent),), (code(joint.child),),
            (vector_span(w, joint.axis),) if joint.type.is_movable else (),
            (vector_span(w, joint.origin.translation),), rpy))
    blocks.append(Paragraph(prose(
        ("Joints, in the order of the velocity vector $v$ (a quaternion joint's rows are its "
         "velocity coordinates, see the next section). " if model.nq > model.dof else
         "Joints, in the order of the joint vector $q$. ")
        + "A joint's origin is the pose of its "
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
                          (vector_span(w, link.inertial.com),),
                          (vector_span(w, [I[0][0], I[1][1], I[2][2],
                                           I[0][1], I[0][2], I[1][2]]),)))
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
             described(par.description))
            for par in sorted(model.parameters, key=lambda par: par.name))
        blocks.append(Paragraph(prose(
            "Parameters: symbols kept in the equations, with the values the description "
            "gives them (used by the sketch and the numeric checks).")))
        blocks.append(Table(tuple(prose(h) for h in ("symbol", "value", "meaning")), par_rows))
    return Section("The robot", tuple(blocks))


def _method_section(model: RobotModel, teaching: bool) -> Section:
    if model.nq > model.dof:
        return chart_method_section(model)
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

def _textbook_sections(dyn: Dynamics, book: TextbookDerivation, coriolis,
                       w: Writer) -> list[Section]:
    model = dyn.model
    n = model.dof
    masses = body_masses(book)
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
            *code_names(b.links), f"), mass ${w.tex(b.mass)}$:")))
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

    sections.append(coriolis_section(book, coriolis, w))

    sections.append(Section("Step 7: the gravity vector", (
        Paragraph(prose("$g_{i} = \\partial P / \\partial q_{i}$ (N m or N):")),
        Equations(tuple(trig_sum(f"g_{{{i + 1}}}", book.g[i]) for i in range(n))))))

    sections.append(_equations_section(dyn, book, coriolis, w))
    return sections


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


def _equations_section(dyn: Dynamics, book: TextbookDerivation, coriolis,
                       w: Writer) -> Section:
    n = dyn.model.dof
    names = coriolis[0]
    masses = body_masses(book)
    qdd = dyn.qdd
    compact, full = [], []
    for i in range(n):
        entry, velocity_terms, gi = compact_terms(dyn, book, coriolis, i)
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


# -- large models ---------------------------------------------------------------------------

def _program_section(dyn: Dynamics, w: Writer) -> Section:
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
                          missing: str | None, hint: str = "Give every parameter a value in "
                          "the description to check the derivation.") -> Section:
    if report is None:
        return Section("Verified properties", (Paragraph(prose(
            "Not checked numerically: ", plain(missing or ""), ". " + hint)),))
    quaternion = dyn.model.nq > dyn.model.dof  # velocities v, not q̇: say it in v
    names, rate = _check_names(quaternion), "v" if quaternion else "\\dot{q}"
    rows = []
    for c in report.checks:
        if c.name == "M positive definite":
            result = prose(f"$\\lambda_{{\\min}} / \\lambda_{{\\max}} \\ge$ {c.max_rel_error:.2g}")
        elif c.how == "exact":
            result = prose("identically zero")
        else:
            result = prose(f"{c.max_abs_error:.1e} (relative {c.max_rel_error:.1e})")
        name = prose(names[c.name]) if c.name in names else (plain(c.name),)
        how = "symbolic" if c.how == "exact" else c.how.split(";")[0]
        rows.append((name, (plain(how),), result, prose("passed" if c.passed else "FAILED")))
    return Section("Verified properties", (
        Paragraph(prose(
            "eomgen checked what it derived (parameters at the values of the table above): "
            "$M$ is symmetric and positive definite, $\\dot{M} - 2C$ is skew-symmetric "
            f"(the energy balance $\\dot{{K}} = {rate}^{{T}} "
            "(\\tau - g)$ depends on it), and "
            "$g$, every column of $M$ and the whole equation agree with an independent "
            "numeric recursive Newton–Euler computation (RNEA) at random states "
            + ("(unit quaternions, joint angles $|q_{i}| \\le \\pi$, velocities $v$ and "
               "accelerations $\\dot{v}$ of order one)." if quaternion else
               "($|q_{i}| \\le \\pi$, velocities and accelerations of order one)."))),
        Table(tuple(prose(h) for h in ("property", "checked", "largest error", "")),
              tuple(rows)),
        Paragraph(prose(
            "All checks passed." if report.passed else
            "SOME CHECKS FAILED: these equations must not be trusted; please report it.")),
    ))


#: The checks of :func:`eomgen.verify` as the handout names them (``$…$`` is math).
CHECK_NAMES = {
    "M symmetric": "$M$ symmetric",
    "M positive definite": "$M$ positive definite",
    "Mdot - 2C skew-symmetric": "$\\dot{M} - 2C$ skew-symmetric",
    "g = RNEA(q,0,0)": "$g(q) = \\mathrm{RNEA}(q, 0, 0)$",
    "M columns = RNEA(q,0,e_i) - RNEA(q,0,0)":
        "$M e_{i} = \\mathrm{RNEA}(q, 0, e_{i}) - \\mathrm{RNEA}(q, 0, 0)$",
    "M qdd + C qd + g = RNEA(q,qd,qdd)":
        "$M \\ddot{q} + C \\dot{q} + g = \\mathrm{RNEA}(q, \\dot{q}, \\ddot{q})$",
}


def _check_names(quaternion: bool) -> dict[str, str]:
    """:data:`CHECK_NAMES`, written in the velocities v and accelerations v̇ of a model with
    quaternion joints (their q̇ is not v)."""
    if not quaternion:
        return CHECK_NAMES
    return {key: text.replace("\\ddot{q}", "\\dot{v}").replace("\\dot{q}", "v")
            for key, text in CHECK_NAMES.items()}


# -- the handout ----------------------------------------------------------------------------

def build_handout(model: RobotModel, progress: Callable[[str], None] = lambda message: None,
                  check: bool = True, scene=None) -> Handout:
    """The handout deriving ``model``'s equations of motion (see the module docstring).

    ``progress`` receives one line per stage (deriving, checking…); ``check=False`` leaves out
    the numeric verification (the section then says so) and the checks of what the handout
    writes with named factors (C, and Ṁ − 2C skew-symmetric: :func:`handout_check`, which
    raises :class:`~eomgen.errors.VerificationError` when one fails); ``scene`` is the
    :class:`~eomgen.reduction.ReductionReport` when ``model`` comes from a scene (a paragraph
    says what was locked, and its contacts get a section).

    >>> import eomgen
    >>> handout = build_handout(eomgen.load(eomgen.example_path("planar_2link")), check=False)
    >>> [s.title for s in handout.sections][:4]
    ['The robot', 'Method and notation', 'Step 1: positions of the centres of mass', 'Step 2: velocities']
    """
    progress(f"deriving the equations of motion of {model.name} ({plural(model.dof, 'joint')})")
    dyn = derive(model, outputs=("M", "C", "g"), simplify=False)
    # the textbook form takes every joint as a coordinate: not a quaternion joint's chart
    book = None if model.nq > model.dof else nt.textbook_for(dyn, HANDOUT_CONFIG)
    extra_names = {HALF: r"\tfrac{1}{2}"}
    if model.nq > model.dof:  # qd, qdd are v and v̇, not the rates of q
        extra_names.update(velocity_names(dyn))
    w = Writer(nt.printing(dyn, HANDOUT_CONFIG, compact_trig=book is not None,
                            extra_names=extra_names))
    spong = spong_dynamics(dyn) if has_drives(model) else None
    contacts = tuple(getattr(scene, "contacts", ()) or ())
    extra_names.update(contact_symbol_names(contacts))
    extra_names.update(loop_symbol_names(model))
    if spong is not None:  # the drives' own symbols, printed by the document's printer
        extra_names.update(drive_symbol_names(spong, w.tex))
    control = has_control_section(book, spong is not None, contacts or model.loops)
    w = Writer(nt.printing(dyn, HANDOUT_CONFIG, compact_trig=book is not None,
                            extra_names=extra_names))
    geometry = sketch_geometry(model)
    pose = ", ".join(f"{v:.3g}" for v in geometry.q)
    where = (f" with its velocity coordinates' chart (virtual joints) at $({pose})$ (rad, m)"
             if model.nq > model.dof else f" at the pose $q = ({pose})$ (rad, m)")
    caption = prose("Kinematic sketch of ", code(model.name), where + ": links as grey "
                    "lines, joints as circles (revolute) or squares (prismatic), centres of "
                    "mass $c_{k}$, gravity $g$.")
    if geometry.placeholder_parameters:
        caption += prose(" Drawn with 1 for the parameters without a value: ",
                         *code_names(geometry.placeholder_parameters), ".")
    sections = [_robot_section(model, w, caption, scene), _method_section(model, book is not None)]
    coriolis = named_coriolis(dyn, book, check) if book is not None else None
    if book is not None:
        sections += _textbook_sections(dyn, book, coriolis, w)
    else:
        sections.append(_program_section(dyn, w))
    if spong is not None:
        sections.append(drives_section(spong, book, coriolis, w))
    if contacts:
        sections.append(contact_section(dyn, contacts, book, coriolis, w))
    if model.loops:
        sections.append(loop_section(dyn, book, coriolis, w))
    if control:
        progress("deriving the Slotine-Li regressor")
        sections.append(control_section(slotine_li_equations(dyn, book, coriolis, check),
                                        book, dyn, w))
    report, missing, hint = None, "the check was switched off", None
    if check:
        progress("checking the derivation against Newton-Euler")
        try:
            report = verify(dyn, samples=VERIFY_SAMPLES)
        except ParameterError as exc:
            missing = str(exc)
        except UnsupportedError as exc:  # a reference eomgen.verify does not have yet
            missing, hint = str(exc), ("eomgen's tests check these equations against "
                                       "Pinocchio instead.")
            progress(f"not checked: {missing}")
    sections.append(_verification_section(dyn, report, missing, *([hint] if hint else [])))
    source = Path(model.source)
    digest = hashlib.sha256(source.read_bytes()).hexdigest() if source.is_file() else "0" * 64
    header = (f"Generated by eomgen {__version__} from {source.name!r} (sha256 {digest[:16]}).",
              "Do not edit by hand: regenerate with `eomgen teach`.")
    title = f"Equations of motion of {model.name}"
    stem = module_name(model.name)
    return Handout(stem, title, tuple(sections),
                   {"sketch": lambda fmt: render_sketch(model, fmt)}, header)
