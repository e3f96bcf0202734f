"""What a handout says of a model with quaternion joints (a free flyer, ball joints:
:mod:`eomgen.model.quaternion`): the configuration ``q`` (NQ entries, with unit quaternions)
and the velocity ``v`` (NV) are not one vector and its rate, so the method section states the
chart instead of Lagrange's equations in ``q``: ``q̇ = Φ(q) v`` with the quaternion's rate
``½ (w ω + ε × ω, −ε · ω)`` (and ``ṗ = R v_lin`` for the free flyer), the equations of motion
``M(q) v̇ + C(q, v) v + g(q) = τ`` in the velocity coordinates, and ``integrate`` (the
exponential map) in place of ``q + v dt``. The printed symbols follow: ``v_k`` and ``v̇_k``
for the velocity inputs (:func:`velocity_names`).
"""

from __future__ import annotations

from .document import Equation, Equations, Paragraph, Section, Table, code, prose


def velocity_names(dyn) -> dict:
    """The LaTeX of the velocity and acceleration symbols of a quaternion model: ``v_{k}``,
    ``\\dot{v}_{k}`` (``qd_k`` and ``qdd_k`` are v and v̇, not the rates of ``q_k``)."""
    names = {s: f"v_{{{k}}}" for k, s in enumerate(dyn.qd, start=1)}
    names.update({s: f"\\dot{{v}}_{{{k}}}" for k, s in enumerate(dyn.qdd, start=1)})
    return names


def chart_joint_names(model) -> list[str]:
    """The names of the joints of ``model`` whose configuration is not their coordinates (the
    free flyer's is ``base``), in velocity order."""
    return [place.name for place in model.joint_places if place.nq != place.nv]


def _layout_rows(model) -> tuple:
    rows = []
    for joint in (place for place in model.joint_places if place.nq != place.nv):
        q = f"$q_{{{joint.q_index + 1}}} \\dots q_{{{joint.q_index + joint.nq}}}$"
        v = f"$v_{{{joint.v_index + 1}}} \\dots v_{{{joint.v_index + joint.nv}}}$"
        word, what_q, what_v = joint.kind.describe()
        rows.append(((code(joint.name),), prose(word),
                     prose(q, ": ", what_q), prose(v, ": ", what_v)))
    return tuple(rows)


def chart_method_section(model) -> Section:
    """The method section of a model with quaternion joints (module docstring)."""
    nq, nv = model.nq, model.dof
    blocks = [
        Paragraph(prose(
            f"The configuration $q$ has {nq} entries and the velocity $v$ has {nv}: the "
            "quaternion joints below hold a unit quaternion in $q$ (four numbers for three "
            "rotational degrees of freedom), and their velocity coordinates are angular (and, "
            "for the free flyer, linear) velocities in a body frame, not the rates of entries "
            "of $q$. The other joints have one entry in each, $q_{k}$ (rad or m) and its rate. "
            "This is Pinocchio's layout: the same arrays feed both.")),
        Table(tuple(prose(h) for h in ("joint", "kind", "configuration entries",
                                        "velocity entries")), _layout_rows(model), small=True),
        Paragraph(prose(
            "So $\\dot{q} \\ne v$: $\\dot{q} = \\Phi(q)\\, v$, where each quaternion "
            "$(\\varepsilon, w)$, $\\varepsilon = (x, y, z)$, turns at")),
        Equations((Equation(r"\dot{\varepsilon}", (r"\tfrac{1}{2} \left(w\, \omega + "
                                                   r"\varepsilon \times \omega\right),",)),
                   Equation(r"\dot{w}", (r"-\tfrac{1}{2}\, \varepsilon^{T} \omega,",)))),
        Paragraph(prose(
            "the free flyer's origin moves at $\\dot{p} = R\\, v_{\\mathrm{lin}}$, and the other "
            "entries at their velocities. The kinetic energy is a quadratic form of $v$, "
            "$K = \\tfrac{1}{2} v^{T} M(q)\\, v$, and Lagrange's equations written in these "
            "velocity coordinates (the Boltzmann–Hamel or Poincaré form) read")),
        Equations((Equation(r"M(q)\, \dot{v} + C(q, v)\, v + g(q)", (r"\tau",)),)),
        Paragraph(prose(
            "with $\\tau$ the effort along each velocity coordinate: for the free flyer the "
            "force and moment on the root, in the root frame (N, N m). $C$ is the Coriolis "
            "matrix Pinocchio's ", code("computeCoriolisMatrix"), " gives, for which "
            "$\\dot{M} - 2C$ is skew-symmetric along the motion. To simulate, integrate "
            "$\\dot{v}$ and move the configuration with the exponential map, "
            "$q \\leftarrow \\mathrm{integrate}(q, v\\, \\Delta t)$ (", code(
                "eomgen.model.configuration.integrate"), ", Pinocchio's ", code("integrate"),
            "), never $q + v\\, \\Delta t$: the quaternion stays a rotation.")),
        Paragraph(prose(
            "How it is derived: each quaternion joint is a chain of virtual one-axis joints "
            "(three rotations about the child frame's $x, y, z$ axes for a ball joint; three "
            "translations, then three rotations, for the free flyer) held at zero, with the "
            "quaternion's rotation placed before them. At the current configuration their "
            "rates are $v$, so $M$ and $g$ come out of the usual recursions; their "
            "second-order terms are corrected ($\\dot{v}$ differs from the chain's "
            "accelerations by the cross products of its rates), which gives the $C$ above. "
            "Symbols: $q_{k}$ is the $k$-th entry of $q$, $v_{k}$ and $\\dot{v}_{k}$ those of "
            "$v$ and $\\dot{v}$; a quaternion is normalised wherever it is used.")),
    ]
    return Section("Method and notation", tuple(blocks))


__all__ = ["chart_joint_names", "chart_method_section", "velocity_names"]
