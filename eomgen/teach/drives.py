"""The handout's section on drives (:mod:`eomgen.analysis.actuators`): Spong's link and motor equations
for flexible joints, or ``M + diag(a)`` and the friction torque for rigid ones, joint by joint
(:func:`drive_equations`, printed by :func:`drives_section`).
"""

from __future__ import annotations

from typing import Callable

import sympy as sp

from ..analysis.actuators import SpongDynamics, joint_actuators
from ..model import RobotModel
from ..present import notation as nt
from ..symbolic.textbook import TextbookDerivation
from .document import Equation, Equations, Paragraph, Section, Table, code, math, prose
from .writer import Writer, code_names, compact_terms


def has_drives(model: RobotModel) -> bool:
    """Whether any joint's actuator adds to the rigid-body equations (armature, friction or
    a stiffness): the handout then gets :func:`drives_section`."""
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
        right the row of ``M q̈ + C q̇ + g`` in the names of
        :func:`~eomgen.teach.writer.compact_terms`, plus ``a_k q̈_k`` and the friction of a
        rigid joint (the spring torque is the placeholder :func:`_spring`). A motor equation
        reads ``τ_{m,k} = B_k θ̈_k + K_k (θ_k − q_k) + τ_f,k(θ̇_k)``. With
        :func:`~eomgen.teach.writer.abbreviation_values` and :func:`spring_values`
        substituted, ``terms − lhs`` are the residuals of
        :meth:`~eomgen.analysis.actuators.SpongDynamics.link_equations` and
        :meth:`~eomgen.analysis.actuators.SpongDynamics.motor_equations` (exact friction).
    """
    dyn = spong.dynamics
    links, motors = [], []
    for k, a in enumerate(spong.actuators):
        entry, velocity, gk = compact_terms(dyn, book, coriolis, k)
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


def _velocities(model, tex: str) -> str:
    """eomgen's own equation ``tex`` with ``q̈``, ``q̇`` read as ``v̇``, ``v`` for a model with
    quaternion joints (its velocity is not the rate of q: :mod:`eomgen.teach.quaternion`)."""
    if model.nq == model.dof:  # v is the rate of q
        return tex
    return tex.replace(r"\ddot{q}", r"\dot{v}").replace(r"\dot{q}", "v")


def drives_section(spong: SpongDynamics, book: TextbookDerivation | None, coriolis,
                    w: Writer) -> Section:
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
            *code_names(flexible), " flexible: an elastic transmission (a spring, stiffness in "
            "N m/rad) sits between the joint and its motor. The motor angle $\\theta_{i}$ "
            "(rad, on the link side of the gear: the rotor angle divided by the gear ratio) "
            "becomes a state of its own beside the link angle $q_{i}$, and the spring passes "
            "its stiffness times $\\theta_{i} - q_{i}$ from the motor to the link. This is "
            "Spong's reduced model: it assumes that the kinetic energy of each motor comes only "
            "from its own spin, one half its motor inertia (the rotor inertia reflected through "
            "the gear, kg m$^{2}$) times $\\dot{\\theta}_{i}^{2}$; the part of the rotor's "
            "angular velocity due to the links that carry it is neglected (the rotor's mass "
            "belongs to the link that carries it)." + friction_text)))
        position = {name: k for k, name in enumerate(model.configuration_names)}
        rows = tuple(((code(names[k]),), prose(f"$q_{{{position[names[k]] + 1}}}$"),
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
            Equation(_velocities(model, r"M(q)\, \ddot{q} + C(q, \dot{q})\, \dot{q} + g(q)"),
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
        blocks.append(Equations((Equation(_velocities(
            model, r"\bigl(M(q) + \operatorname{diag}(a)\bigr)\, \ddot{q} + C(q, \dot{q})\, "
            r"\dot{q} + g(q) + \tau_{f}(\dot{q})"), (r"\tau,",)),)))
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
