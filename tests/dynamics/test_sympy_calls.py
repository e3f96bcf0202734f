"""``dyn.M``, ``dyn.C``, ``dyn.g`` in SymPy's own functions, whatever their size (issue 29):
``sympify``, ``Matrix``, ``latex``, ``simplify`` and ``lambdify`` of the bundled robots, the
Panda and a random 5-joint arm with every inertial parameter a symbol (that one stays
:class:`~eomgen.symbolic.named.ProgramMatrix`), with the numbers of ``dyn.lambdify()``."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.model import Inertial, Parameter, build_model, parameter_symbol
from eomgen.robots import example_path
from support import assert_close, erd_robots_dir
from support.reference import random_robot
from support.robots import panda

BUNDLED = ("cylindrical_rpp", "elbow_rrr", "planar_2link", "puma560_arm3", "puma560_dh",
           "scara_rrp", "stanford_rrp")


def symbolic_inertials(model):
    """``model`` with each numeric mass, centre-of-mass coordinate and inertia entry of every
    link a parameter (``m_link2``, ``cy_link2``, ``Ixz_link2``), its value the default."""
    parameters = list(model.parameters)

    def symbol(name, link, value):
        value = sp.sympify(value)
        if not value.is_Number:
            return value
        parameters.append(Parameter(parameter_symbol(f"{name}_{link}"), float(value)))
        return parameters[-1].symbol

    links = []
    for link in model.links:
        inertial = link.inertial
        if inertial is None:
            links.append(link)
            continue
        names = ("xx", "xy", "xz"), ("xy", "yy", "yz"), ("xz", "yz", "zz")
        upper = {(i, j): symbol(f"I{names[i][j]}", link.name, inertial.inertia[i][j])
                 for i in range(3) for j in range(i, 3)}
        inertia = [[upper[min(i, j), max(i, j)] for j in range(3)] for i in range(3)]
        links.append(replace(link, inertial=Inertial(
            symbol("m", link.name, inertial.mass),
            [symbol(f"c{a}", link.name, c) for a, c in zip("xyz", inertial.com)], inertia)))
    return build_model(model.source, model.name, links, model.joints, gravity=model.gravity,
                       parameters=parameters)


#: The random arms (seed, joints) with every inertial parameter symbolic: too large to write
#: out, so their M, C and g all stay named and reach SymPy through the protocol. One arm: a
#: 7-joint one took the same path (whole expansion refused, then entry by entry, each entry
#: written out or a function of its inputs) at three times the cost.
RANDOM_ARMS = {"random 5-joint, symbolic": (2, 5)}


def model_named(which):
    if which == "panda":
        if erd_robots_dir() is None:
            pytest.skip("example-robot-data is not installed (the test extra)")
        return panda()
    if which in RANDOM_ARMS:
        seed, n = RANDOM_ARMS[which]
        arm = random_robot(np.random.default_rng(seed), n, prismatic=False, fixed_links=False)
        return symbolic_inertials(arm)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the PUMA's published inertias are not physical
        return eomgen.load(example_path(which))


# One case per robot, so that a parallel run spreads them.
@pytest.mark.slow
@pytest.mark.parametrize("which", [*BUNDLED, "panda", *RANDOM_ARMS])
def test_sympy_functions_take_M_C_g_of_every_size(which):
    named = 0
    model = model_named(which)
    dyn = eomgen.derive(model)
    numeric = dyn.lambdify()
    values = {p.symbol: p.value for p in model.parameters}
    parameters = list(values)
    rng = np.random.default_rng(0)
    q, qd = rng.uniform(-1, 1, model.dof), rng.uniform(-1, 1, model.dof)
    for name in ("M", "C", "g"):
        X = getattr(dyn, name)
        named += type(X).__name__ == "ProgramMatrix"
        what = f"{which}: {name}"
        S = sp.sympify(X)
        assert isinstance(S, sp.MatrixBase) and S.shape == X.shape, what
        assert sp.Matrix(X) == S, what
        last = X[X.rows - 1, X.cols - 1]
        for tex in (sp.latex(X), sp.latex(last)):
            assert "ProgramMatrix" not in tex and "mathtt" not in tex, what
        assert isinstance(sp.sympify(last), sp.Expr), what
        # simplify on the entry of fewest operations (SymPy's simplify of a written-out
        # entry of hundreds of terms takes minutes, whoever calls it)
        smallest = min(S, key=sp.count_ops)
        assert isinstance(sp.simplify(smallest), sp.Expr), what
        inputs = [dyn.q, dyn.qd] if name == "C" else [dyn.q]
        f = sp.lambdify(inputs + [parameters], X)
        got = np.asarray(f(*[q, qd][:len(inputs)], [values[p] for p in parameters]), float)
        expected = (numeric.C(q, qd) if name == "C" else getattr(numeric, name)(q))
        assert_close(got.reshape(np.shape(expected)), expected, what)
    if which in RANDOM_ARMS:  # they stayed named: the test reached the SymPy protocol
        assert named == 3
