"""The C kernels backend (``kernels``): the fast module's arithmetic as plain C functions with a
header, called from a C and a C++ program without Python, against the NumPy module."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

import eomgen
from eomgen.codegen.backends.casadi_backend import c_compiler, library_name
from eomgen.codegen.generate import render_files
from support import load_module
from support.extras import need

FUNCTIONS = ["inverse_dynamics", "inverse_dynamics_derivatives", "forward_dynamics_aba"]

MAIN = r"""
#include <stdio.h>
#include "planar_2link_kernels.h"
int main(void)
{
    double q[PLANAR_2LINK_NQ], qd[PLANAR_2LINK_NV], x[PLANAR_2LINK_NV];
    double tau[PLANAR_2LINK_NV], d[PLANAR_2LINK_NV * 2 * PLANAR_2LINK_NV], qdd[PLANAR_2LINK_NV];
    int k;
    for (k = 0; k < PLANAR_2LINK_NV; ++k) {
        q[k] = 0.3 + 0.5 * k; qd[k] = -0.7 + k; x[k] = 1.1 - 0.4 * k;
    }
    planar_2link_inverse_dynamics(q, qd, x, planar_2link_parameter_defaults, tau);
    planar_2link_inverse_dynamics_derivatives(q, qd, x, planar_2link_parameter_defaults, d);
    planar_2link_forward_dynamics_aba(q, qd, x, planar_2link_parameter_defaults, qdd);
    for (k = 0; k < PLANAR_2LINK_NV; ++k) printf("%.17g ", tau[k]);
    for (k = 0; k < PLANAR_2LINK_NV * 2 * PLANAR_2LINK_NV; ++k) printf("%.17g ", d[k]);
    for (k = 0; k < PLANAR_2LINK_NV; ++k) printf("%.17g ", qdd[k]);
    printf("\n");
    return 0;
}
"""


@pytest.mark.skipif(c_compiler() is None, reason="needs a C compiler")
def test_kernels_called_from_c_and_cpp_equal_the_numpy_module(tmp_path):
    model = eomgen.load(eomgen.example_path("planar_2link"))
    for f in render_files(model, ["kernels", "numpy"], functions=FUNCTIONS):
        (tmp_path / f.name).write_text(f.content, encoding="utf-8")
    numpy_module = load_module(tmp_path / "planar_2link_numpy.py", "planar_2link_numpy")
    q, qd, x = np.array([0.3, 0.8]), np.array([-0.7, 0.3]), np.array([1.1, 0.7])
    dq, dqd = numpy_module.inverse_dynamics_derivatives(q, qd, x)
    expected = np.concatenate([numpy_module.inverse_dynamics(q, qd, x),
                               np.hstack([dq, dqd]).ravel(),
                               numpy_module.forward_dynamics_aba(q, qd, x)])
    (tmp_path / "main.c").write_text(MAIN, encoding="utf-8")
    programs = [(c_compiler(), ["-std=c99"], "main.c")]
    if shutil.which("g++"):
        (tmp_path / "main.cpp").write_text(MAIN, encoding="utf-8")
        programs.append(("g++", [], "main.cpp"))
    for compiler, flags, main in programs:
        kernels = tmp_path / "planar_2link_kernels.c"
        objects = []
        if main.endswith(".cpp"):  # the kernels stay C; the header's extern "C" links them
            subprocess.run([c_compiler(), "-O1", "-std=c99", "-c", str(kernels), "-o",
                            str(tmp_path / "kernels.o")], check=True)
            objects, kernels = [str(tmp_path / "kernels.o")], None
        exe = tmp_path / (main + ".out")
        subprocess.run([compiler, *flags, "-O1", "-Wall", "-Werror", "-I", str(tmp_path),
                        str(tmp_path / main), *([str(kernels)] if kernels else []), *objects,
                        "-o", str(exe), "-lm"], check=True)
        out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
        got = np.array([float(v) for v in out.split()])
        np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-13, err_msg=compiler)


@pytest.mark.skipif(c_compiler() is None, reason="needs a C compiler")
def test_casadi_c_library_linearize_equals_the_numpy_module(tmp_path):
    casadi = need("casadi")
    model = eomgen.load(eomgen.example_path("planar_2link"))
    for f in render_files(model, ["c", "numpy"], functions=["linearize"]):
        path = tmp_path / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    numpy_module = load_module(tmp_path / "planar_2link_numpy.py", "planar_2link_numpy_c")
    library = tmp_path / library_name("planar_2link")
    linearize = casadi.external("linearize", str(library))
    q, qd, tau = np.array([0.3, -0.8]), np.array([0.5, 0.2]), np.array([1.0, -2.0])
    out = linearize.call({"q": q, "qd": qd, "tau": tau, "m2": 1.7})
    A, B = numpy_module.linearize(q, qd, tau, m2=1.7)
    np.testing.assert_allclose(np.array(out["A_lin"]), A, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(np.array(out["B_lin"]), B, rtol=1e-13, atol=1e-13)
    assert not np.allclose(B, numpy_module.linearize(q, qd, tau)[1])  # m2 was passed on
