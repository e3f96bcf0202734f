"""A parameter is passed by its name in the description, in every backend: the planar arm's
gravity ``g`` is ``gravity_vector(q, g=1.62)``, though the modules name the gravity vector ``g``
themselves (inside their functions the parameter has another identifier). A name no keyword can
be (a Python keyword) is renamed, and a call by the old name says the new one."""

from __future__ import annotations

import dataclasses
import importlib.util
import re
import sysconfig

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.codegen.backends.casadi_backend import library_name
from eomgen.codegen.generate import generate
from eomgen.common.compiler import c_compiler
from eomgen.model import Parameter
from support import load_module
from support.extras import need

STEM = "planar_2link"
MOON = 1.62
STATES = np.array([[0.3, -0.7], [-1.2, 0.4], [2.0, 1.1]])


def closed_form_gravity(q, g):
    """g(q) of the planar arm of the description (gravity along -y, m = l = 1, lc = 0.5):
    g1 = (m1 lc1 + m2 l1) g cos q1 + m2 lc2 g cos(q1 + q2), g2 = m2 lc2 g cos(q1 + q2)."""
    q1, q2 = q
    return np.array([1.5 * g * np.cos(q1) + 0.5 * g * np.cos(q1 + q2),
                     0.5 * g * np.cos(q1 + q2)])


def present(module: str) -> bool:
    return importlib.util.find_spec(module) is not None


@pytest.fixture(scope="module")
def arm():
    return eomgen.load(eomgen.example_path("planar_2link"))


@pytest.fixture(scope="module")
def folder(arm, tmp_path_factory):
    """The bundled arm's modules of every backend whose tools are here."""
    backends = ["numpy", "kernels"] + [b for b, needs in (
        ("casadi", "casadi"), ("c", "casadi"), ("fast", "numpy"), ("jax", "jax"),
        ("torch", "torch")) if present(needs)]
    out = tmp_path_factory.mktemp("keywords")
    generate(arm, out, backends, cache=False)
    return out


def module_of(folder, backend):
    if backend == "fast":
        suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
        path = folder / f"{STEM}_fast{suffix}"
        if not path.exists():
            pytest.skip("the fast module was not built (no C compiler or Python headers)")
        return load_module(path, f"{STEM}_fast")
    return load_module(folder / f"{STEM}_{backend}.py", f"keywords_{backend}")


PYTHON_BACKENDS = {"numpy": "numpy", "fast": "numpy", "jax": "jax", "torch": "torch"}


@pytest.mark.parametrize("backend", PYTHON_BACKENDS)
def test_gravity_is_the_keyword_g_in_each_python_module(folder, backend):
    need(PYTHON_BACKENDS[backend], reason=f"the {backend} backend")
    module = module_of(folder, backend)
    if backend == "jax":
        import jax

        jax.config.update("jax_enable_x64", True)
    assert module.PARAMETERS["g"] == 9.81 and "g_" not in module.PARAMETERS
    for q in STATES:
        moon = np.asarray(module.gravity_vector(q, g=MOON), dtype=float)
        np.testing.assert_allclose(moon, closed_form_gravity(q, 9.81) * MOON / 9.81,
                                   rtol=1e-12, atol=1e-12)
    with pytest.raises(TypeError, match="g_"):
        module.gravity_vector(STATES[0], g_=MOON)
    # a composed function passes g on: forward dynamics at rest holding the Moon's gravity
    q, zero = STATES[0], np.zeros(2)
    tau = np.asarray(module.gravity_vector(q, g=MOON), dtype=float)
    np.testing.assert_allclose(np.asarray(module.forward_dynamics(q, zero, tau, g=MOON),
                                          dtype=float), zero, atol=1e-12)


def test_gravity_is_the_input_g_of_the_casadi_functions_and_their_c_library(folder):
    casadi = need("casadi", reason="the CasADi backend")
    module = module_of(folder, "casadi")
    functions = [module.gravity_vector]
    if c_compiler() is not None:
        functions.append(casadi.external("gravity_vector", str(folder / library_name(STEM))))
    for function in functions:
        assert function.name_in() == ["q", "I1", "I2", "g", "l1", "l2", "lc1", "lc2", "m1", "m2"]
        for q in STATES:
            moon = np.array(function(q=q, g=MOON)["g"]).ravel()
            np.testing.assert_allclose(moon, closed_form_gravity(q, MOON), rtol=1e-12,
                                       atol=1e-12)
    assert list(module.PARAMETERS) == ["I1", "I2", "g", "l1", "l2", "lc1", "lc2", "m1", "m2"]


def test_the_c_kernels_name_the_parameter_g(folder):
    header = (folder / f"{STEM}_kernels.h").read_text(encoding="utf-8")
    names = re.search(r"#define PLANAR_2LINK_PARAMETER_NAMES \{(.*)\}", header)[1]
    assert names.split(", ") == [f'"{n}"' for n in module_of(folder, "numpy").PARAMETERS]
    assert '"g"' in names.split(", ")


def test_lambdify_takes_g(arm):
    f = eomgen.derive(arm).lambdify()
    assert "g" in f.parameters and "g_" not in f.parameters
    for q in STATES:
        np.testing.assert_allclose(f.g(q, g=MOON), closed_form_gravity(q, MOON), rtol=1e-12,
                                   atol=1e-12)


# ----------------------------------------------------------------------------------------------
# A name no keyword can be
# ----------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def keyworded(arm, tmp_path_factory):
    """The arm with its second mass named ``lambda`` (a Python keyword; the YAML parser refuses
    such a name, a model built in Python need not), and its modules."""
    m2 = next(p for p in arm.parameters if p.name == "m2")
    lam = sp.Symbol("lambda", real=True)
    model = arm.substitute({m2.symbol: lam})
    model = dataclasses.replace(model, parameters=model.parameters + (
        Parameter(lam, 1.0, "mass of link 2 [kg]"),))
    backends = ["numpy"] + [b for b, needs in (("casadi", "casadi"), ("fast", "numpy"),
                                                ("jax", "jax"), ("torch", "torch"))
                            if present(needs)]
    out = tmp_path_factory.mktemp("keyworded")
    generate(model, out, backends, cache=False)
    return model, out


@pytest.mark.parametrize("backend", PYTHON_BACKENDS)
def test_a_python_keyword_parameter_is_renamed_and_its_old_name_says_so(keyworded, backend):
    need(PYTHON_BACKENDS[backend], reason=f"the {backend} backend")
    model, out = keyworded
    module = module_of(out, backend)
    assert "lambda_" in module.PARAMETERS and "lambda" not in module.PARAMETERS
    q = STATES[0]
    heavy = np.asarray(module.gravity_vector(q, lambda_=3.0), dtype=float)
    g1 = (0.5 + 3.0) * 9.81 * np.cos(q[0]) + 3.0 * 0.5 * 9.81 * np.cos(q.sum())
    np.testing.assert_allclose(heavy, [g1, 3.0 * 0.5 * 9.81 * np.cos(q.sum())], rtol=1e-12)
    with pytest.raises(TypeError, match=r"gravity_vector\(\).*'lambda'.*keyword 'lambda_'"):
        module.gravity_vector(q, **{"lambda": 3.0})
    with pytest.raises(TypeError, match="unexpected keyword argument 'lamda'"):
        module.gravity_vector(q, lamda=3.0)  # any other name: the usual error


def test_a_python_keyword_parameter_is_renamed_in_casadi_and_its_old_name_says_so(keyworded):
    need("casadi", reason="the CasADi backend")
    model, out = keyworded
    module = module_of(out, "casadi")
    f = module.gravity_vector
    assert "lambda_" in f.name_in()
    q = STATES[0]
    heavy = np.array(f(q=q, lambda_=3.0)["g"]).ravel()
    assert np.isclose(heavy[1], 3.0 * 0.5 * 9.81 * np.cos(q.sum()), rtol=1e-12)
    with pytest.raises(TypeError, match=r"gravity_vector.*'lambda'.*input 'lambda_'"):
        f.call({"q": q, "lambda": 3.0})
