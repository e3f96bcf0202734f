"""The handout's section on adaptive control (issue 28, docs/control.md): the Slotine–Li
regressor ``M q̈_r + C q̇_r + g = Y(q, q̇, q̇_r, q̈_r) β`` written out entry by entry, the base
parameters β, the law ``τ = Y β̂ − K_D s`` with ``β̂̇ = −Γ Yᵀ s``, and the Lyapunov argument
``V̇ = −sᵀ K_D s`` resting on ``sᵀ (Ṁ − 2C) s = 0``, with ``Ṁ`` and ``Ṁ − 2C`` written out.

The regressor and β come from :func:`eomgen.derive` (outputs ``Y_SL_base`` and ``beta``);
Ṁ − 2C from the textbook M and step 6's C (:func:`slotine_li_equations`); the section only
prints them (:func:`control_section`). Teaching-sized fixed-base models only: the handout adds
it when it prints the textbook derivation and the model has no drives and no contacts
(:func:`has_control_section`).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..dynamics import Dynamics, derive
from ..errors import VerificationError
from ..present import readability as rd
from ..regressor.generated import generated_base
from ..regressor.notation import parameter_latex
from ..symbolic.identities import ZeroCheck, check_zero
from ..symbolic.textbook import TextbookDerivation
from ..symbolic.trigonometry import simplify_trig
from .document import Equation, Equations, Paragraph, Section, prose
from .writer import Writer


def has_control_section(book: TextbookDerivation | None, drives: bool, contacts) -> bool:
    """Whether the handout gets :func:`control_section`: the textbook derivation is printed
    (a teaching-sized model) and the robot is a plain rigid arm: no drives, and no contacts
    or loop closures (``contacts`` is true for either)."""
    return book is not None and not drives and not contacts


@dataclass(frozen=True)
class ControlEquations:
    """What the section prints, derived once.

    Attributes
    ----------
    qd_r, qdd_r:
        The symbols of q̇_r and q̈_r (``qd_r1``, ``qdd_r1``, … of :attr:`Dynamics.input_symbols`).
    names:
        The base parameters' names (``MX1R``, …), in the columns' order, without those in
        ``zero``.
    beta:
        β as expressions of the description's parameters (the ``beta`` output), without those
        in ``zero``.
    Y:
        The base Slotine–Li regressor, n × b, each entry in the textbook's trigonometric form
        (:meth:`~eomgen.symbolic.textbook.TextbookDerivation.trig_form`), without the columns
        of ``zero``: ``M q̈_r + C(q, q̇) q̇_r + g = Y β``.
    zero:
        The names of the base parameters that are zero for every value of the description's
        parameters (``MY1`` of an arm whose centres of mass lie on the links' x axes): left
        out, with their columns.
    M_dot, N:
        Ṁ = Σ_k ∂M/∂q_k q̇_k and N = Ṁ − 2C, written with step 6's named factors.
    skew:
        The check that N + Nᵀ = 0 (exactly, or to a tolerance when the model has floats);
        None when the handout is made without checks.
    """

    qd_r: tuple
    qdd_r: tuple
    names: tuple[str, ...]
    beta: tuple[sp.Expr, ...]
    Y: sp.Matrix
    M_dot: sp.Matrix
    N: sp.Matrix
    zero: tuple[str, ...] = ()
    skew: ZeroCheck | None = None


def handout_check(dyn: Dynamics, statement: str, residual, scale) -> ZeroCheck:
    """:func:`~eomgen.symbolic.identities.check_zero` of an identity the handout states;
    raises :class:`~eomgen.errors.VerificationError` (one line naming the description) when
    it fails."""
    result = check_zero(statement, residual, scale)
    if not result.holds:
        raise VerificationError(f"{dyn.model.source}: a check of the handout failed: {result}; "
                                "--no-check writes the handout without its checks")
    return result


def slotine_li_equations(dyn: Dynamics, book: TextbookDerivation, coriolis,
                         check: bool = True) -> ControlEquations:
    """Derive the section's equations (``coriolis``: :func:`~eomgen.teach.content.
    named_coriolis`'s names, Christoffel symbols and C); ``check``: check that Ṁ − 2C is
    skew-symmetric (:func:`handout_check`)."""
    model = dyn.model
    sl = derive(model, outputs=("Y_SL_base", "beta"), simplify=False)
    # in the trigonometric form of steps 1-7 (products s_2 c_2, never sin 2q_2)
    Y = book.trig_form(sl.named("Y_SL_base").expand())
    beta = tuple(sp.factor_terms(sp.expand(b)) for b in sl.named("beta").expand())
    names = tuple(generated_base(model).names)
    kept = [k for k, b in enumerate(beta) if b != 0]  # β_k = 0 for every parameter value
    zero = tuple(name for k, name in enumerate(names) if k not in kept)
    Y = Y.extract(list(range(Y.rows)), kept)
    beta, names = tuple(beta[k] for k in kept), tuple(names[k] for k in kept)
    names_h, _, C = coriolis
    # Ṁ = Σ_k ∂M/∂q_k q̇_k = C + Cᵀ, since ∂M_ij/∂q_k = Γ_ijk + Γ_jik: in step 6's names
    # when it has them (every Γ is then a multiple of one), else in the textbook's form
    if names_h:
        M_dot = (C + C.T).applyfunc(sp.factor)
        N = (C.T - C).applyfunc(sp.factor)
    else:
        M_dot = book.trig_form(C + C.T)
        N = book.trig_form(C.T - C)
    skew = None
    if check:   # Ṁ = C + Cᵀ against M differentiated: then Ṁ − 2C = Cᵀ − C is skew-symmetric
        values = {nf.symbol: nf.value for nf in names_h}
        derivative = sp.zeros(model.dof, model.dof)
        for k, qk in enumerate(dyn.q):
            derivative += book.M.diff(qk) * dyn.qd[k]
        skew = handout_check(
            dyn, "Mdot written as C + C^T is dM/dt, so Mdot - 2C = C^T - C is skew-symmetric",
            (M_dot.subs(values) - derivative).applyfunc(
                lambda e: sp.expand(simplify_trig(e, dyn.q))), derivative)
    vectors = sl.input_symbols
    return ControlEquations(tuple(vectors["qd_r"]), tuple(vectors["qdd_r"]), names, beta, Y,
                            M_dot, N, zero, skew)


def _zero_clause(zero: tuple[str, ...]) -> str:
    """What the section says of the base parameters that are identically zero."""
    if not zero:
        return ""
    names = [f"${parameter_latex(name)}$" for name in zero]
    listed = names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]
    one = len(zero) == 1
    return (f", of which {listed} {'is' if one else 'are'} zero for every value of this "
            f"robot's parameters and {'is' if one else 'are'} left out with "
            f"{'its column' if one else 'their columns'} of $Y$")


def control_section(eqs: ControlEquations, book: TextbookDerivation, dyn: Dynamics,
                    w: Writer) -> Section:
    n, b = eqs.Y.shape
    angles = list(dyn.q)
    beta_tex = [parameter_latex(name) for name in eqs.names]
    blocks: list = [
        Paragraph(prose(
            "To make the robot follow a desired motion $q_{d}(t)$ when its masses and inertias "
            "are known only roughly, the adaptive controller of Slotine and Li estimates them "
            "while it tracks. With the tracking error $\\tilde{q} = q - q_{d}$ and a gain "
            "matrix $\\Lambda > 0$ it defines a reference velocity and acceleration and the "
            "sliding variable $s$ (when $s = 0$, $\\dot{\\tilde{q}} = -\\Lambda \\tilde{q}$ "
            "and the error dies out):")),
        Equations((
            Equation(r"\dot{q}_{r}", (r"\dot{q}_{d} - \Lambda \tilde{q},",)),
            Equation(r"\ddot{q}_{r}", (r"\ddot{q}_{d} - \Lambda \dot{\tilde{q}},",)),
            Equation("s", (r"\dot{q} - \dot{q}_{r} = \dot{\tilde{q}} + \Lambda \tilde{q}.",)))),
        Paragraph(prose(
            "The equations of motion are linear in the inertial parameters, and so is "
            "$M(q)\\, \\ddot{q}_{r} + C(q, \\dot{q})\\, \\dot{q}_{r} + g(q)$, with $C$ the "
            "Coriolis matrix of step 6 multiplied by $\\dot{q}_{r}$ and not by "
            f"$\\dot{{q}}$. In the {b + len(eqs.zero)} base parameters (the combinations that "
            "the motion can reveal; the superscript $R$ marks a parameter with others grouped "
            "into it)" + _zero_clause(eqs.zero) + ":")),
        Equations(tuple(Equation(tex, (w.tex(value) + ("," if k < b - 1 else "."),))
                        for k, (tex, value) in enumerate(zip(beta_tex, eqs.beta)))),
        Paragraph(prose(
            "it reads $M \\ddot{q}_{r} + C \\dot{q}_{r} + g = Y(q, \\dot{q}, \\dot{q}_{r}, "
            "\\ddot{q}_{r})\\, \\beta$, the Slotine–Li regressor. Entry $Y_{i,k}$ is the "
            "coefficient of $\\beta_{k}$ in row $i$; with $\\dot{q}_{r} = \\dot{q}$ and "
            "$\\ddot{q}_{r} = \\ddot{q}$ it is the joint torque regressor. Its non-zero "
            "entries (columns in the order of $\\beta$ above):")),
    ]
    entries, zero = [], []
    for k in range(b):
        for i in range(n):
            lhs = rf"Y_{{{i + 1},{k + 1}}}"
            if eqs.Y[i, k] == 0:
                zero.append(f"${lhs}$")
                continue
            entries.append(w.terms(lhs, rd.by_trig(eqs.Y[i, k], angles)))
    blocks.append(Equations(tuple(entries)))
    if zero:
        blocks.append(Paragraph(prose("The other entries, " + ", ".join(zero)
                                      + ", are zero.")))
    blocks += [
        Paragraph(prose(
            "With an estimate $\\hat{\\beta}$ of $\\beta$, gain matrices $K_{D} > 0$ and "
            "$\\Gamma > 0$, the control law and the adaptation law are")),
        Equations((
            Equation(r"\tau", (r"Y \hat{\beta} - K_{D}\, s,",)),
            Equation(r"\dot{\hat{\beta}}", (r"-\Gamma\, Y^{T} s.",)))),
        Paragraph(prose(
            "Subtracting $M \\ddot{q}_{r} + C \\dot{q}_{r} + g = Y \\beta$ from the equations "
            "of motion gives the closed loop $M \\dot{s} + C s + K_{D} s = Y \\tilde{\\beta}$ "
            "with $\\tilde{\\beta} = \\hat{\\beta} - \\beta$. Its Lyapunov function and "
            "derivative (the robot's parameters are constant, so "
            "$\\dot{\\tilde{\\beta}} = \\dot{\\hat{\\beta}}$) are")),
        Equations((
            Equation("V", (r"\tfrac{1}{2} s^{T} M s + \tfrac{1}{2} \tilde{\beta}^{T} "
                           r"\Gamma^{-1} \tilde{\beta},",)),
            Equation(r"\dot{V}", (
                r"s^{T} M \dot{s} + \tfrac{1}{2} s^{T} \dot{M} s + \tilde{\beta}^{T} "
                r"\Gamma^{-1} \dot{\hat{\beta}}",)),
            Equation("", (r"s^{T} (Y \tilde{\beta} - C s - K_{D} s) + \tfrac{1}{2} s^{T} "
                          r"\dot{M} s - \tilde{\beta}^{T} Y^{T} s",)),
            Equation("", (r"-s^{T} K_{D}\, s + \tfrac{1}{2} s^{T} (\dot{M} - 2C)\, s.",)))),
        Paragraph(prose(
            "The last term vanishes because $\\dot{M} - 2C$ is skew-symmetric for the $C$ of "
            "the Christoffel symbols. Differentiating $M$ of step 5 along the motion, "
            "$\\dot{M} = \\sum_{k} \\partial M / \\partial q_{k}\\, \\dot{q}_{k}$, and with "
            "$C$ of step 6:")),
        Equations(w.matrix(r"\dot{M}", eqs.M_dot) + w.matrix(r"\dot{M} - 2C", eqs.N)),
        *_float_note(eqs.skew),
        Paragraph(prose(
            "$(\\dot{M} - 2C)^{T} = -(\\dot{M} - 2C)$, so $s^{T} (\\dot{M} - 2C)\\, s = 0$ for "
            "every $s$ and $\\dot{V} = -s^{T} K_{D}\\, s \\le 0$: $s$ and the tracking error "
            "go to zero, and $\\hat{\\beta}$ goes to $\\beta$ when the desired motion is rich "
            "enough (persistently exciting). Another matrix $C'$ with the same "
            "$C' \\dot{q}$ keeps the equations of motion but not the skew symmetry, and the "
            "argument fails: the regressor must multiply $\\dot{q}_{r}$ by this $C$.")),
    ]
    return Section("Adaptive control: the Slotine–Li regressor", tuple(blocks))


def _float_note(skew: ZeroCheck | None) -> tuple:
    """A paragraph saying to what tolerance the skew symmetry was checked when the model has
    floating-point numbers (none when it was checked exactly, or not at all)."""
    if skew is None or skew.exact:
        return ()
    return (Paragraph(prose(
        "The model has floating-point numbers, so the entries above carry rounding errors: "
        f"eomgen checked the skew symmetry to {skew.tolerance:g} relative (largest residual "
        f"{skew.residual:.1e}), not exactly.")),)


__all__ = ["ControlEquations", "control_section", "handout_check", "has_control_section",
           "slotine_li_equations"]
