"""Verification reports (:func:`eomgen.verify.verify`): they pass on correct dynamics, and each
check fails on the kind of error it exists to catch.

Wrong dynamics are made by corrupting the outputs of a correct straight-line program (the
intermediates stay as derived), so every failure below is the verifier's doing. Two
corruptions show why both the skew-symmetry check and the equation check are needed:

* ``C → Cᵀ`` keeps ``Ṁ − 2C`` skew-symmetric (``Ṁ = C + Cᵀ``) but changes ``C q̇``: only the
  equation check fails;
* ``C → C + D`` with ``D q̇ = 0`` (``D = e₁ wᵀ``, ``w = q̇₂ e₁ − q̇₁ e₂``) keeps ``C q̇`` and so
  the whole equation, but ``D`` is not skew: only the skew check fails.
"""

from __future__ import annotations

import dataclasses
import functools
import warnings

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.dynamics import ALL_OUTPUTS, Dynamics, derive
from eomgen.errors import DescriptionError
from eomgen.model import (
    Inertial,
    Joint,
    JointType,
    Link,
    Parameter,
    Transform,
    build_model,
    parameter_symbol,
    vec3,
)
from eomgen.robots import example_path
from eomgen.symbolic.program import Program
from eomgen.verify import verify
from support.reference import random_inertial, random_robot

SYMMETRIC = "M symmetric"
PD = "M positive definite"
SKEW = "Mdot - 2C skew-symmetric"
GRAVITY = "g = RNEA(q,0,0)"
COLUMNS = "M columns = RNEA(q,0,e_i) - RNEA(q,0,0)"
EQUATION = "M qdd + C qd + g = RNEA(q,qd,qdd)"
TAU = "symbolic Newton-Euler tau = M qdd + C qd + g"
CHECKS = (SYMMETRIC, PD, SKEW, GRAVITY, COLUMNS, EQUATION)


def failed(report) -> set[str]:
    return {c.name for c in report.checks if not c.passed}


def how(report) -> dict[str, str]:
    return {c.name: c.how for c in report.checks}


@functools.cache
def planar() -> Dynamics:
    return derive(eomgen.load(example_path("planar_2link")))


@functools.cache
def puma() -> Dynamics:
    return derive(eomgen.load(example_path("puma560_dh")))


def massive_random_robot(seed: int, n: int, tree: bool):
    """A random robot (reference.random_robot) in which every link has mass and inertia, so
    that M is positive definite (a massless leaf on a prismatic joint would make it singular)."""
    rng = np.random.default_rng(seed)
    model = random_robot(rng, n, tree=tree)
    links = tuple(link if link.inertial is not None else Link(link.name, random_inertial(rng))
                  for link in model.links)
    return build_model(model.source, model.name, links, model.joints, model.gravity)


def corrupted(dyn: Dynamics, name: str, change) -> Dynamics:
    """``dyn`` with output ``name`` replaced by ``change(matrix)``; nothing else touched."""
    program = dyn.program
    outputs = tuple((n, change(m) if n == name else m) for n, m in program.outputs)
    return dataclasses.replace(dyn, program=Program(program.assignments, outputs))


def null_perturbation(dyn: Dynamics) -> sp.Matrix:
    """D = e₁ wᵀ with w = q̇₂ e₁ − q̇₁ e₂: D q̇ = 0 for every q̇, and D + Dᵀ ≠ 0."""
    n = dyn.model.dof
    qd = dyn.qd
    D = sp.zeros(n, n)
    D[0, 0], D[0, 1] = qd[1], -qd[0]
    assert (D * sp.Matrix(qd)).applyfunc(sp.expand) == sp.zeros(n, 1)
    return D


# ----------------------------------------------------------------------------------------------
# Correct dynamics pass
# ----------------------------------------------------------------------------------------------


def test_planar_2link_passes_with_exact_checks():
    report = verify(planar())
    assert report.passed, report.format()
    assert [c.name for c in report.checks] == list(CHECKS)
    assert how(report)[SYMMETRIC] == how(report)[SKEW] == "exact"
    assert how(report)[GRAVITY] == "20 samples"
    assert report.format().splitlines()[-1] == "all checks passed"
    assert report.robot == "planar_2link"


def test_puma560_passes():
    report = verify(puma(), samples=10, seed=1)
    assert report.passed, report.format()
    assert how(report)[SKEW] == "10 samples"  # six joints and floats: sampled, not exact
    pd = next(c for c in report.checks if c.name == PD)
    assert 0 < pd.max_rel_error < 1  # smallest / largest eigenvalue


@pytest.mark.parametrize("seed, n, tree", [(1, 3, True), (2, 4, False), (4, 6, True)])
def test_random_robot_passes(seed, n, tree):
    report = verify(derive(massive_random_robot(seed, n, tree)), samples=5, seed=seed)
    assert report.passed, report.format()
    assert how(report)[SKEW] == "5 samples"  # float models are never checked "exactly"


def test_inverse_dynamics_output_is_checked_too():
    dyn = derive(planar().model, outputs=ALL_OUTPUTS)
    report = verify(dyn, samples=5)
    assert report.passed and TAU in how(report), report.format()
    wrong = corrupted(dyn, "tau", lambda tau: tau + sp.Matrix([dyn.qd[0], 0]))
    assert failed(verify(wrong, samples=5)) == {TAU}


def test_same_seed_same_report():
    assert verify(planar(), samples=4, seed=3) == verify(planar(), samples=4, seed=3)


# ----------------------------------------------------------------------------------------------
# Wrong dynamics fail the checks meant to catch them
# ----------------------------------------------------------------------------------------------


@pytest.fixture(params=["planar", "puma"])
def dyn(request) -> Dynamics:
    """The exact path (planar, symbolic reduction) and the sampled path (PUMA, floats)."""
    return planar() if request.param == "planar" else puma()


def test_wrong_gravity_fails_gravity_and_equation(dyn):
    report = verify(corrupted(dyn, "g", lambda g: g * sp.Rational(101, 100)), samples=5)
    assert failed(report) == {GRAVITY, EQUATION}, report.format()
    assert not report.passed
    assert report.format().splitlines()[-1] == "SOME CHECKS FAILED"
    assert f"  FAIL {GRAVITY}" in report.format()


def test_gravity_with_wrong_sign_fails(dyn):
    assert failed(verify(corrupted(dyn, "g", lambda g: -g), samples=5)) == {GRAVITY, EQUATION}


def test_symmetric_error_in_C_fails_skew_and_equation(dyn):
    """C + q̇₁·1: N + Nᵀ = −4 q̇₁·1 ≠ 0, and C q̇ changes."""
    n = dyn.model.dof
    report = verify(corrupted(dyn, "C", lambda C: C + dyn.qd[0] * sp.eye(n)), samples=5)
    assert failed(report) == {SKEW, EQUATION}, report.format()


def test_transposed_C_fails_only_the_equation(dyn):
    report = verify(corrupted(dyn, "C", lambda C: C.T), samples=5)
    assert failed(report) == {EQUATION}, report.format()


def test_C_error_invisible_in_the_equation_fails_the_skew_check(dyn):
    D = null_perturbation(dyn)
    report = verify(corrupted(dyn, "C", lambda C: C + D), samples=5)
    assert failed(report) == {SKEW}, report.format()


def test_asymmetric_M_fails_symmetry_columns_and_equation():
    dyn = planar()
    q2 = dyn.q[1]

    def change(M):
        M = M.copy()
        M[0, 1] += sp.cos(q2) / 10
        return M

    report = verify(corrupted(dyn, "M", change), samples=5)
    assert {SYMMETRIC, COLUMNS, EQUATION} <= failed(report), report.format()
    assert GRAVITY not in failed(report)


def test_scaled_M_fails_columns_equation_and_skew():
    """2M is still symmetric positive definite, but no longer matches RNEA, and its Ṁ no longer
    matches C: N + Nᵀ = 4Ṁ − 2(C + Cᵀ) = 2Ṁ ≠ 0."""
    report = verify(corrupted(planar(), "M", lambda M: 2 * M), samples=5)
    assert failed(report) == {COLUMNS, EQUATION, SKEW}, report.format()


def slider_model():
    """A revolute joint carrying a massless link on a prismatic joint: M has a zero row and
    column, so it is singular although everything else is right."""
    m, g = parameter_symbol("m"), parameter_symbol("g")
    links = [Link("base"), Link("arm", Inertial(m, vec3([1, 0, 0]),
                                                ((1, 0, 0), (0, 1, 0), (0, 0, 1)))),
             Link("slider")]
    joints = [
        Joint("turn", JointType.REVOLUTE, "base", "arm", Transform(), vec3([0, 0, 1])),
        Joint("slide", JointType.PRISMATIC, "arm", "slider", Transform.from_xyz_rpy([1, 0, 0]),
              vec3([1, 0, 0])),
    ]
    return build_model("<test>", "slider", links, joints, gravity=[0, -g, 0],
                       parameters=[Parameter(m, 2.0), Parameter(g, 9.81)])


def test_singular_mass_matrix_fails_positive_definiteness():
    dyn = derive(slider_model())
    assert dyn.M[1, 1] == 0
    report = verify(dyn, samples=5)
    assert failed(report) == {PD}, report.format()
    pd = next(c for c in report.checks if c.name == PD)
    assert abs(pd.max_rel_error) < 1e-12  # smallest eigenvalue / largest: zero
    assert how(report)[SKEW] == "exact"


def test_giving_the_slider_mass_makes_it_pass():
    model = slider_model()
    links = tuple(Link("slider", Inertial(1, vec3([0, 0, 0]), ((1, 0, 0), (0, 1, 0), (0, 0, 1))))
                  if link.name == "slider" else link for link in model.links)
    report = verify(derive(dataclasses.replace(model, links=links)), samples=5)
    assert report.passed, report.format()


# ----------------------------------------------------------------------------------------------
# What verify refuses
# ----------------------------------------------------------------------------------------------


def test_needs_M_C_and_g():
    with pytest.raises(ValueError, match="C was not derived"):
        verify(derive(planar().model, outputs=["M", "g"]))


def test_needs_parameter_values():
    model = slider_model()
    m = parameter_symbol("m")
    no_value = dataclasses.replace(model, parameters=tuple(
        Parameter(p.symbol) if p.symbol == m else p for p in model.parameters))
    with pytest.raises(DescriptionError, match="verification needs a value for m"):
        verify(derive(no_value))


def test_verify_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        verify(planar(), samples=3)


# ----------------------------------------------------------------------------------------------
# Joints that move no mass: named by the model check, against the rows of M from Newton–Euler
# ----------------------------------------------------------------------------------------------

_ARM = ('<link name="base"/><link name="upper"><inertial><origin xyz="0.5 0 0"/>'
        '<mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>'
        '</inertial></link>'
        '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
        '<axis xyz="0 0 1"/></joint>')


def _tip(mass="0", inertia=(0, 0, 0)) -> str:
    ixx, iyy, izz = inertia
    return (f'<link name="tip"><inertial><mass value="{mass}"/><inertia ixx="{ixx}" ixy="0" '
            f'ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial></link>')


def _wrist(kind="revolute", axis="0 0 1") -> str:
    return (f'<joint name="wrist" type="{kind}"><parent link="upper"/><child link="tip"/>'
            f'<origin xyz="1 0 0" rpy="0.3 0 0"/><axis xyz="{axis}"/></joint>')


_HAND = ('<link name="hand"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" '
         'iyz="0" izz="0.2"/></inertial></link>')


@pytest.mark.parametrize("parts, expected", [
    ([_tip(), _wrist()], [("wrist", ("tip",))]),  # no mass, no inertia
    (['<link name="tip"/>', _wrist()], [("wrist", ("tip",))]),  # no <inertial>
    ([_tip(inertia=(0.2, 0, 0)), _wrist()], [("wrist", ("tip",))]),  # inertia across the axis
    ([_tip(inertia=(0, 0, 0.2)), _wrist()], []),  # inertia about the axis
    ([_tip(inertia=(0.2, 0.2, 0.2)), _wrist("prismatic")], [("wrist", ("tip",))]),
    ([_tip(mass="0.1"), _wrist("prismatic")], []),
    # a link fixed to the tip carries mass: merged, the wrist moves it
    ([_tip(), _wrist(), '<link name="sensor"><inertial><mass value="0.1"/><inertia ixx="0" '
      'ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link><joint name="bolt" '
      'type="fixed"><parent link="tip"/><child link="sensor"/><origin xyz="0 0.1 0"/></joint>'],
     []),
    # inertia about z of a hand turned about x (roll): the wrist moves it, the roll does not
    ([_tip(), _wrist(), _HAND, '<joint name="roll" type="revolute"><parent link="tip"/>'
      '<child link="hand"/><axis xyz="1 0 0"/></joint>'], [("roll", ("hand",))]),
    # the hand turns about the wrist's own axis: its moment about z stays; x-only would not
    ([_tip(), _wrist(), _HAND.replace('izz="0.2"', 'izz="0"').replace('ixx="0"', 'ixx="0.2"'),
      '<joint name="yaw" type="revolute"><parent link="tip"/><child link="hand"/>'
      '<axis xyz="0 0 1"/></joint>'], [("wrist", ("tip", "hand")), ("yaw", ("hand",))]),
])
def test_joints_that_move_no_mass_are_the_zero_rows_of_M(parts, expected):
    from eomgen.model import massless_joints
    from eomgen.parsers.urdf import parse_urdf_string
    from eomgen.verify import reference_rnea

    model = parse_urdf_string("<robot name='r'>" + _ARM + "".join(parts) + "</robot>",
                              defer_notices=True)
    assert list(massless_joints(model)) == expected
    rnea, n = reference_rnea(model), model.dof
    rng = np.random.default_rng(1)
    zero_rows = set(range(n))
    for _ in range(3):
        q, zeros = rng.uniform(-np.pi, np.pi, n), np.zeros(n)
        M = np.column_stack([rnea(q, zeros, e) - rnea(q, zeros, zeros) for e in np.eye(n)])
        zero_rows &= {i for i in range(n) if np.abs(M[i]).max() < 1e-12}
    assert sorted(zero_rows) == sorted(model.joint_names.index(j) for j, _ in expected)


def test_verify_runs_beside_an_output_that_takes_tau():
    """A derivation holding the ABA's q̈ (inputs q, q̇, τ) is verified on its M, C, g as one
    without it: the output that takes τ is left out of the evaluation instead of leaving τ
    unbound (it raised NameError: tau1)."""
    import eomgen
    from eomgen.verify import verify
    model = eomgen.load(eomgen.example_path("planar_2link"))
    plain = verify(eomgen.derive(model), samples=3)
    with_aba = verify(eomgen.derive(model, outputs=("M", "C", "g", "qdd_aba")), samples=3)
    assert [c.name for c in with_aba.checks] == [c.name for c in plain.checks]
    assert all(c.passed for c in with_aba.checks)
    assert [c.max_rel_error for c in with_aba.checks] == [c.max_rel_error for c in plain.checks]
