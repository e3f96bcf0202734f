"""A Jupyter notebook walking through the derivation of one robot's equations of motion
(``eomgen notebook``).

Sections, each a short explanation followed by a code cell using eomgen's API: loading the
robot; for teaching-sized models (at most :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_DOF`
joints and :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_OPERATIONS` program operations) the
textbook derivation (centre-of-mass positions, Jacobians, kinetic and potential energy per link,
M, Christoffel symbols, C, g); the equations of motion; for the same models the regressor
Y (τ = Y π, columns named) and the base parameters as expressions of the standard ones
(:func:`eomgen.regressor.regressor_form`); the property checks of
:func:`eomgen.verify`; a comparison with the numeric Newton–Euler algorithm at a sample state;
and a short simulation (SciPy's ``solve_ivp``) with a plot.

The notebook is saved without outputs and holds no timestamp: the same description gives the
same file, byte for byte.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import nbformat
from nbformat import v4

from .dynamics import derive
from .errors import ParameterError
from .model import RobotModel
from .present.notation import teaching_sized
from .symbolic.textbook import TEXTBOOK_MAX_DOF, TEXTBOOK_MAX_OPERATIONS
from .teach.embedded import load_cells, text_literal  # noqa: F401  (text_literal re-exported)


def _teaching_sized(model: RobotModel) -> bool:
    """Whether the notebook shows the textbook derivation: the bound of the LaTeX document and
    the display, checked on the straight-line program before anything is expanded."""
    return teaching_sized(derive(model, simplify=False))


def build_notebook(model: RobotModel, description: Path | None = None,
                   scene: Path | None = None, check: bool = True,
                   at: Path | None = None) -> nbformat.NotebookNode:
    """The derivation notebook of ``model``, loaded from ``description`` (None: the bundled
    planar 2-link arm) and reduced by the scene file ``scene`` when given (``model`` is then the
    reduced model, see :func:`eomgen.reduction.apply_scene`). ``check=False`` (``--no-check``)
    leaves out the checks (:func:`eomgen.verify`, Ṁ − 2C skew-symmetric, the asserted
    comparisons): the notebook says so and only prints the numbers.

    The symbolic check of Ṁ − 2C is exact for a model with exact numbers and holds to
    :data:`~eomgen.symbolic.identities.FLOAT_TOLERANCE` when the model has floating-point
    numbers (:func:`~eomgen.symbolic.identities.check_zero`); the cell prints which.

    The description's text (and the scene's) is written into the notebook, which therefore
    runs wherever it is copied; a description naming files of its own (an MJCF's meshes or
    includes) is loaded by its path relative to ``at``, where the notebook will be written
    (None: the current folder).

    Raises
    ------
    ParameterError
        When a parameter has no value: the notebook's checks, comparison with Newton–Euler and
        simulation are numeric, and would fail cell by cell.
    """
    missing = [p.name for p in model.parameters if p.value is None]
    if missing:
        raise ParameterError(model.source, "parameters",
                             "the notebook's numeric cells need a value for "
                             + ", ".join(missing))
    chart = bool(model.quaternion_joints)  # q (NQ) and v (NV) differ: no textbook form
    small = not chart and model.dof <= TEXTBOOK_MAX_DOF and _teaching_sized(model)
    cells = []

    def md(text: str) -> None:
        cells.append(v4.new_markdown_cell(text.strip()))

    def code(text: str) -> None:
        cells.append(v4.new_code_cell(text.strip()))

    if chart:
        md(_CHART_INTRO.format(name=model.name, nq=model.nq, nv=model.dof,
                               joints=", ".join(f"`{j.name}`" for j in model.quaternion_joints)))
    else:
        md(f"""
# Equations of motion of `{model.name}`

This notebook derives the equations of motion

$$M(q)\\,\\ddot q + C(q, \\dot q)\\,\\dot q + g(q) = \\tau$$

of the robot with the Lagrangian method, step by step, with eomgen, then checks them and
simulates the robot.
Compact notation: $s_{{1}} = \\sin q_1$, $c_{{12}} = \\cos(q_1 + q_2)$.
""")
    about, texts, load = load_cells(description, scene, at)
    md("## The robot\n\n" + about + " `eomgen.load` makes a `RobotModel` of it: links, "
       "joints, gravity and parameters.")
    for text in texts:
        code(text)
    code(f"""
import tempfile
from pathlib import Path

import numpy as np
import sympy as sp
from IPython.display import Math, display

import eomgen
from eomgen.display import expression_latex

{load}
dyn = eomgen.derive(model)


def show(name, expr):
    display(Math(name + " = " + expression_latex(dyn, expr)))


model
""")
    if small:
        md("""
## Positions of the centres of mass and Jacobians

For each moving body $i$, the position $p_{c_i}(q)$ of its centre of mass in the world frame,
the linear velocity Jacobian $J_{v_i} = \\partial p_{c_i} / \\partial q$ and the angular velocity
Jacobian $J_{\\omega_i}$ (column $k$ is the world axis of joint $k$ when it is a revolute joint
at or before body $i$), so that $v_{c_i} = J_{v_i} \\dot q$ and $\\omega_i = J_{\\omega_i} \\dot q$.
""")
        code("""
from eomgen.symbolic.textbook import textbook_derivation

book = textbook_derivation(model)
for i, body in enumerate(book.bodies, start=1):
    print(f"body {i}: joint {body.joint}, links {', '.join(body.links)}")
    show(f"p_{{c{i}}}", body.com)
    show(f"J_{{v{i}}}", body.J_v)
    show(f"J_{{\\\\omega{i}}}", body.J_w)
""")
        md("""
## Kinetic and potential energy of each link

$K_i = \\tfrac12 m_i v_{c_i}^T v_{c_i} + \\tfrac12 \\omega_i^T R_i I_{c_i} R_i^T \\omega_i$ and
$P_i = -m_i\\, g_{vec}^T p_{c_i}$; the totals are $K = \\sum_i K_i$ and $P = \\sum_i P_i$.
""")
        code("""
for i, body in enumerate(book.bodies, start=1):
    show(f"K_{{{i}}}", body.K)
    show(f"P_{{{i}}}", body.P)
show("K", book.K)
show("P", book.P)
""")
        md("""
## Mass matrix

$M = \\sum_i m_i J_{v_i}^T J_{v_i} + J_{\\omega_i}^T R_i I_{c_i} R_i^T J_{\\omega_i}$, so that
$K = \\tfrac12 \\dot q^T M \\dot q$: the same matrix as `dyn.M`, which `eomgen.derive`
computes without expanding the intermediate expressions. Each entry is grouped by body mass,
as the LaTeX document and the handout print it.
""")
        code("""
from eomgen.display import grouped_matrices

grouped = grouped_matrices(book)
show("M", grouped["M"])
""")
        md("""
## Christoffel symbols

$\\Gamma_{ijk} = \\tfrac12 \\left(\\frac{\\partial M_{ij}}{\\partial q_k}
+ \\frac{\\partial M_{ik}}{\\partial q_j} - \\frac{\\partial M_{jk}}{\\partial q_i}\\right)$;
the non-zero ones with $j \\le k$ ($\\Gamma_{ijk} = \\Gamma_{ikj}$), indices from 1 (written
$c_{ijk}$ in many textbooks; here $c$ is a cosine).
""")
        code("""
for (i, j, k), value in book.christoffel:
    show(f"\\\\Gamma_{{{i + 1}{j + 1}{k + 1}}}", value)
""")
        md("## Coriolis matrix\n\n$C_{ij} = \\sum_k \\Gamma_{ijk} \\dot q_k$: with this choice "
           "$\\dot M - 2C$ is skew-symmetric.")
        code('show("C", book.C)')
        md("## Gravity vector\n\n$g_i = \\partial P / \\partial q_i$, grouped by trigonometric "
           "factor.")
        code('show("g", grouped["g"])')
    else:
        md(f"""
## Derivation

`{model.name}` has {model.dof} joints: the body-by-body textbook derivation (expanded
expressions, exponential in the number of joints) is shown for models of at most
{TEXTBOOK_MAX_DOF} joints whose program has at most {TEXTBOOK_MAX_OPERATIONS} operations.
`eomgen.derive` computes M, C and g as a straight-line program without expression swell; its
size (`dyn.lambdify()` turns it into NumPy functions):
""")
        code('{name: dyn.operation_count([name]) for name in dyn.outputs}')
    md("## The equations of motion\n\n" + (
        "$M(q)\\,\\dot v + C(q, v)\\,v + g(q) = \\tau$, in the order of the velocity "
        "coordinates (`dyn.qd` are the entries of $v$, `dyn.qdd` those of $\\dot v$, `dyn.q` "
        "the NQ entries of $q$):" if chart else
        "$M(q)\\,\\ddot q + C(q, \\dot q)\\,\\dot q + g(q) = \\tau$, in joint order:"))
    code("print(dyn.joint_names)\ndyn")
    if small:
        md("""
## Linear in the parameters: the regressor

The equations of motion are linear in the inertial parameters of the bodies,
$\\tau = Y(q, \\dot q, \\ddot q)\\,\\pi$. Body $k$ has ten, in its own frame (joint $k$'s frame
after the joint has moved): mass $\\mathrm{M}_k$, first moment $(\\mathrm{MX}_k, \\mathrm{MY}_k,
\\mathrm{MZ}_k) = m_k c_k$, and inertia $\\mathrm{XX}_k, \\mathrm{XY}_k, \\mathrm{YY}_k,
\\mathrm{XZ}_k, \\mathrm{YZ}_k, \\mathrm{ZZ}_k$ about the frame's origin: one column of $Y$ each.
Columns that are zero are listed; the others are shown one by one.
""")
        code("""
from eomgen.regressor import parameter_latex, regressor_form

form = regressor_form(model)
reg = form.regressor
print("zero columns:", ", ".join(reg.PARAMETER_NAMES[k] for k in form.zero))
display(Math(r"\\pi = " + expression_latex(dyn, form.pi.T, form.latex_names) + "^T"))
for c, name in enumerate(form.names):
    display(Math(r"Y_{:,\\," + parameter_latex(name) + "} = "
                 + expression_latex(dyn, form.Y[:, c], form.latex_names)))
# the check, at a sample state: Y pi with the description's pi is M qdd + C qd + g
at = dict(zip([*dyn.q, *dyn.qd, *dyn.qdd], np.linspace(0.3, 1.1, 3 * model.dof)))
at.update(model.parameter_values)
pi = reg.inertial_parameters().extract(list(form.columns), [0])
tau = dyn.M * sp.Matrix(dyn.qdd) + dyn.C * sp.Matrix(dyn.qd) + dyn.g
print("largest |Y pi - tau|:", max(abs(float(e)) for e in (form.Y * pi - tau).xreplace(at)))
""")
        md("""
## Base parameters

Some columns of $Y$ are combinations of others: only the base parameters $\\beta$ can be
identified from joint efforts, $\\tau = Y_{base}\\,\\beta$, with $Y_{base}$ the base columns of
$Y$. Each is a column's parameter with the parameters grouped into it (marked $R$), as
expressions of the standard ones and of the geometry.
""")
        code("""
for k, name, expr in zip(form.base, form.base_names, form.beta):
    if expr != reg.parameter_symbols[k]:  # the grouped ones
        display(Math(parameter_latex(name) + " = "
                     + expression_latex(dyn, expr, form.latex_names)))
print("base parameters:", ", ".join(form.base_names))
# the check, at the same state and a random pi: Y_base beta = Y pi
at.update(zip(reg.parameter_symbols, np.random.default_rng(0).uniform(0.5, 1.5, reg.p)))
print("largest |Y_base beta - Y pi|:",
      max(abs(float(e)) for e in (form.Y_base * sp.Matrix(form.beta) - form.Y * form.pi).xreplace(at)))
""")
    if small:
        md("""
## Adaptive control: the Slotine–Li regressor

With $\\tilde q = q - q_d$, the reference velocity $\\dot q_r = \\dot q_d - \\Lambda \\tilde q$
and $s = \\dot q - \\dot q_r$, the adaptive controller of Slotine and Li applies
$\\tau = Y(q, \\dot q, \\dot q_r, \\ddot q_r)\\,\\hat\\beta - K_D s$ and adapts
$\\dot{\\hat\\beta} = -\\Gamma Y^T s$, where $Y \\beta = M \\ddot q_r + C \\dot q_r + g$ (the
base parameters $\\beta$). With $V = \\tfrac12 s^T M s + \\tfrac12 \\tilde\\beta^T \\Gamma^{-1}
\\tilde\\beta$, $\\dot V = -s^T K_D s + \\tfrac12 s^T (\\dot M - 2C) s = -s^T K_D s$: the
skew symmetry of $\\dot M - 2C$ for the Christoffel $C$, checked below, is what the regressor
needs (docs/control.md).
""")
        code("""
n = model.dof
sl = eomgen.derive(model, outputs=("Y_SL_base", "beta"))
Y_SL = sl.named("Y_SL_base").expand()
beta = sl.named("beta").expand()
# the base parameters, named as in the handout (MX1R: MX1 with others grouped into it); those
# that are zero for every value of this robot's parameters are listed, their columns left out
from eomgen.regressor.generated import generated_base

names = generated_base(model).names
print("zero for every parameter value:", ", ".join(
    name for name, value in zip(names, beta) if value == 0) or "none")
for k, (name, value) in enumerate(zip(names, beta)):
    if value != 0:  # Y's column in the trigonometric form of the cells above (s2 c2, c12)
        show(parameter_latex(name), value)
        show(f"Y_{{:,\\,{parameter_latex(name)}}}", book.trig_form(Y_SL[:, k]))
# Mdot - 2C is skew-symmetric
M_dot = sum((dyn.M.diff(qk) * qdk for qk, qdk in zip(dyn.q, dyn.qd)), sp.zeros(n, n))
N = M_dot - 2 * dyn.C
show("\\\\dot{M} - 2C", N.applyfunc(sp.simplify))
{skew_check}# the check, at a state: Y_SL beta = M qdd_r + C qd_r + g
qd_r, qdd_r = sl.input_symbols["qd_r"], sl.input_symbols["qdd_r"]
at = dict(zip([*dyn.q, *dyn.qd, *qd_r, *qdd_r], np.linspace(0.3, 1.4, 4 * n)))
at.update(model.parameter_values)
tau_r = dyn.M * sp.Matrix(qdd_r) + dyn.C * sp.Matrix(qd_r) + dyn.g
print("largest |Y_SL beta - (M qdd_r + C qd_r + g)|:",
      max(abs(float(e)) for e in (Y_SL * beta - tau_r).xreplace(at)))
""".replace("{skew_check}", _SKEW_CHECK if check else ""))
    if chart:
        _chart_checks(md, code, check)
    else:
        _checks(md, code, check)
    nb = v4.new_notebook(cells=cells, metadata={
        "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
        "language_info": {"name": "python"},
    })
    for k, cell in enumerate(nb.cells):  # deterministic ids (nbformat makes random ones)
        cell["id"] = f"cell-{k:02d}"
    return nb


#: The simulation cell of the notebook: the parts that differ between a model without and with
#: quaternion joints (q̇ = v, or configuration_rate and normalised quaternions) are filled in.
_SIMULATION = """
import io

import matplotlib
from IPython.display import Image

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from scipy.integrate import solve_ivp
{setup}
budget = 50_000
calls = 0


class OverBudget(Exception):
    pass


def rhs(t, state):
    global calls
    calls += 1
    if calls > budget:
        raise OverBudget
{rhs}

t_all, y_all = [0.0], [np.concatenate([q0, np.zeros(n)])]
for start in np.arange(0.0, 2.0, 0.1):
    try:
        chunk = solve_ivp(rhs, (start, start + 0.1), y_all[-1], rtol=1e-8, atol=1e-10,
                          t_eval=np.linspace(start, start + 0.1, 11)[1:])
    except OverBudget:
        print(f"stopped at t = {{start:.1f}} s after {{budget}} evaluations: the robot is stiff")
        break
    assert chunk.success, chunk.message
    t_all += list(chunk.t)
{collect}
fig, ax = plt.subplots(figsize=(7, 3.5))
for k, name in enumerate(dyn.joint_names):
    ax.plot(t_all, {plotted}[k], label=name)
ax.set_xlabel("time [s]")
ax.set_ylabel({ylabel})
ax.legend({legend})
ax.set_title(f"{{model.name}}: free motion from rest")
fig.tight_layout()
buffer = io.BytesIO()
fig.savefig(buffer, format="png", dpi=100)
plt.close(fig)
display(Image(buffer.getvalue()))
"""
_JOINT_SPACE = {
    "setup": "\n",
    "rhs": '''    q, qd = state[:n], state[n:]
    out = evaluate(*q, *qd, *values)
    qdd = np.linalg.solve(out["M"], -out["C"] @ qd - out["g"][:, 0])
    return np.concatenate([qd, qdd])
''',
    "collect": '''    y_all += list(chunk.y.T)
t_all, y_all = np.array(t_all), np.array(y_all).T''',
    "plotted": "y_all", "ylabel": '"joint position"', "legend": ""}
_CHART_SPACE = {
    "setup": "\nnq = model.nq",
    "rhs": '''    q, v = state[:nq], state[nq:]
    out = evaluate(*q, *v, *values)
    vdot = np.linalg.solve(out["M"], -out["C"] @ v - out["g"][:, 0])
    return np.concatenate([configuration_rate(q, v, model), vdot])


def normalised(state):
    state = state.copy()
    for joint in model.quaternion_joints:
        k = joint.quaternion
        state[k:k + 4] /= np.linalg.norm(state[k:k + 4])
    return state
''',
    "collect": '''    y_all += [normalised(y) for y in chunk.y.T]
t_all = np.array(t_all)
moved = np.array([difference(q0, y[:nq], model=model) for y in y_all]).T''',
    "plotted": "moved", "ylabel": '"difference(q0, q)"', "legend": 'fontsize="small"'}


#: The check of the Slotine–Li cell: exact, or to a stated tolerance for a model with floats.
_SKEW_CHECK = """from eomgen.symbolic.identities import check_zero

skew = check_zero("Mdot - 2C is skew-symmetric", (N + N.T).applyfunc(sp.simplify), N)
print(skew)
assert skew.holds, str(skew)
"""

#: What the notebook says in place of its checks under ``--no-check``.
_NO_CHECK = """
## Checks left out

This notebook was written with `eomgen notebook --no-check`: it neither runs `eomgen.verify`
nor checks that $\\dot M - 2C$ is skew-symmetric, and the comparisons below print their
numbers without asserting them.
"""

#: The property checks of a model without quaternion joints.
_VERIFY_TEXT = """
## Property checks

`eomgen.verify` checks that M is symmetric positive definite, that $\\dot M - 2C$ is
skew-symmetric, and M, C, g and the whole equation against an independent numeric recursive
Newton–Euler computation at random states.
"""
_VERIFY_CODE = """
report = eomgen.verify(eomgen.derive(model, outputs=("M", "C", "g", "tau")), samples=5)
print(report.format())
assert report.passed
"""


def _checks(md, code, check: bool = True) -> None:
    """The cells of a model without quaternion joints: eomgen.verify, the comparison with the
    numeric Newton–Euler and the simulation (``check=False``: no verify, no assertions)."""
    if not check:
        md(_NO_CHECK)
    else:
        md(_VERIFY_TEXT)
        code(_VERIFY_CODE)
    md("""
## Comparison with Newton–Euler at a sample state

The torques $\\tau = M \\ddot q + C \\dot q + g$ from the derived program against
`eomgen.numeric.rnea`, the numeric recursive Newton–Euler algorithm.
""")
    code("""
from eomgen.numeric import numeric_model, rnea
from eomgen.symbolic.evaluate import compile_program

params = [p.symbol for p in model.parameters]
values = [model.parameter_values[p] for p in params]
evaluate = compile_program(dyn.program, list(dyn.q) + list(dyn.qd) + params)
nm = numeric_model(model)

n = model.dof
q0 = np.linspace(0.3, 0.9, n)
qd0 = np.linspace(-0.5, 0.7, n)
qdd0 = np.linspace(1.0, -1.0, n)
out = evaluate(*q0, *qd0, *values)
tau = out["M"] @ qdd0 + out["C"] @ qd0 + out["g"][:, 0]
tau_rnea = rnea(nm, q0, qd0, qdd0)
print("tau (derived):", tau)
print("tau (RNEA):   ", tau_rnea)
print("largest difference:", np.max(np.abs(tau - tau_rnea)))
""" + ("assert np.allclose(tau, tau_rnea, rtol=1e-9, atol=1e-9)\n" if check else ""))
    md("""
## A short simulation

Forward dynamics $\\ddot q = M^{-1}(\\tau - C \\dot q - g)$ with $\\tau = 0$ (the robot falls
under gravity), integrated with SciPy's `solve_ivp` in steps of 0.1 s. A very stiff robot (a
tiny inertia next to a large one) would need millions of steps: the simulation stops after
`budget` evaluations of the dynamics and says so, so that the notebook always finishes.
""")
    code(_SIMULATION.format(**_JOINT_SPACE))


_CHART_INTRO = """
# Equations of motion of `{name}`

`{name}` has quaternion joints ({joints}): its configuration $q$ has {nq} entries, with a
unit quaternion $(x, y, z, w)$ per quaternion joint (and the free flyer's origin), and its
velocity $v$ has {nv}: the root twist in the root frame (linear, then angular) for a free
flyer, the angular velocity in the child frame for a ball joint, the rates of the other
joints. This is Pinocchio's layout. So $\\dot q \\ne v$: a quaternion $(\\varepsilon, w)$
turns at $\\dot\\varepsilon = \\tfrac12 (w\\,\\omega + \\varepsilon \\times \\omega)$,
$\\dot w = -\\tfrac12 \\varepsilon^T \\omega$, the free flyer's origin at $R\\,v_{{lin}}$
(`eomgen.quaternion_joints.configuration_rate`). The equations of motion are written in the
velocity coordinates,

$$M(q)\\,\\dot v + C(q, v)\\,v + g(q) = \\tau,$$

with $K = \\tfrac12 v^T M v$ and $C$ Pinocchio's `computeCoriolisMatrix` ($\\dot M - 2C$
skew-symmetric along the motion). A simulation integrates $\\dot v$ and moves $q$ with the
exponential map, `eomgen.quaternion_joints.integrate(q, v, dt)`, never $q + v\\,dt$. The
body-by-body textbook derivation takes every joint as a coordinate, so this notebook shows
the derivation as a program, then checks it and simulates the robot.
"""

#: The property checks of a model with quaternion joints: eomgen.verify where it has a
#: reference for them.
_CHART_VERIFY_TEXT = """
## Property checks

`eomgen.verify` checks M, C, g and the whole equation against an independent numeric
Newton–Euler computation where it has one for quaternion joints; otherwise it says why, and
the next cell compares with Pinocchio.
"""
_CHART_VERIFY_CODE = """
try:
    report = eomgen.verify(eomgen.derive(model, outputs=("M", "C", "g", "tau")), samples=5)
    print(report.format())
    assert report.passed
except eomgen.UnsupportedError as exc:
    print("not checked by eomgen.verify:", exc)
"""


def _chart_checks(md, code, check: bool = True) -> None:
    """The cells of a model with quaternion joints: eomgen.verify where it has a reference
    (else its reason is printed), M, C, g and τ against Pinocchio (when installed) at a
    configuration from ``integrate``, and a simulation moving q with ``configuration_rate``
    (``check=False``: no verify, no assertions)."""
    if not check:
        md(_NO_CHECK)
    else:
        md(_CHART_VERIFY_TEXT)
        code(_CHART_VERIFY_CODE)
    md("""
## Comparison with Pinocchio at a sample state

$M$, $C v$, $g$ and $\\tau = M \\dot v + C v + g$ from the derived program against
Pinocchio's `crba`, `computeCoriolisMatrix`, `computeGeneralizedGravity` and `rnea` on the
same arrays (`eomgen.numeric.pinocchio.to_pinocchio` builds its model with
`JointModelFreeFlyer` and `JointModelSpherical`). The configuration comes from `integrate`:
the neutral one (identity quaternions) moved by a velocity for one second.
""")
    code("""
from eomgen.quaternion_joints import configuration_rate, difference, integrate, neutral
from eomgen.symbolic.evaluate import compile_program

params = [p.symbol for p in model.parameters]
values = [model.parameter_values[p] for p in params]
evaluate = compile_program(dyn.program, list(dyn.q) + list(dyn.qd) + params)

n = model.dof
q0 = integrate(neutral(model), np.linspace(0.3, 0.9, n), 1.0, model=model)
qd0 = np.linspace(-0.5, 0.7, n)
qdd0 = np.linspace(1.0, -1.0, n)
out = evaluate(*q0, *qd0, *values)
tau = out["M"] @ qdd0 + out["C"] @ qd0 + out["g"][:, 0]
try:
    import pinocchio
except ImportError:
    print("Pinocchio is not installed (pip install pin): no comparison")
else:
    from eomgen.numeric.pinocchio import to_pinocchio

    pm = to_pinocchio(model)
    tau_pin = pm.rnea(q0, qd0, qdd0)
    print("largest |tau - rnea|:", np.max(np.abs(tau - tau_pin)))
    print("largest |M - crba|:", np.max(np.abs(out["M"] - pm.crba(q0))))
""" + ("    assert np.allclose(tau, tau_pin, rtol=1e-9, atol=1e-9)\n" if check else ""))
    md("""
## A short simulation

$\\dot v = M^{-1}(\\tau - C v - g)$ with $\\tau = 0$ (the robot falls under gravity), and
$\\dot q = $ `configuration_rate(q, v)`, integrated with SciPy's `solve_ivp` in steps of
0.1 s; the quaternions are normalised after each step (`integrate` would keep them unit).
The plot shows `difference(q0, q(t))`: how far each velocity coordinate has carried the robot.
A very stiff robot would need millions of steps: the simulation stops after `budget`
evaluations of the dynamics and says so.
""")
    code(_SIMULATION.format(**_CHART_SPACE))


def write_notebook(nb: nbformat.NotebookNode, path: Path) -> Path:
    """Write ``nb`` to ``path`` atomically (a temporary file in the same folder, then
    :func:`os.replace`): a reader never sees half a notebook."""
    path = Path(path)
    nbformat.validate(nb)
    text = nbformat.writes(nb)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path
