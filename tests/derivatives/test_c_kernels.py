"""The C kernels backend (``kernels``): the fast module's arithmetic as plain C functions with a
header, called from a C and a C++ program without Python, against the NumPy module."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

import eomgen
from eomgen.codegen.backends import fast_backend
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


BATCH_MAIN = r"""
#include <stdio.h>
#include "planar_2link_kernels.h"
#define N 11
static const double states[N][3][PLANAR_2LINK_NV] = {%(states)s};
int main(void)
{
    double q[N * PLANAR_2LINK_NV], qd[N * PLANAR_2LINK_NV], x[N * PLANAR_2LINK_NV];
    double tau[N * PLANAR_2LINK_NV], d[N * PLANAR_2LINK_NV * 2 * PLANAR_2LINK_NV];
    double qdd[N * PLANAR_2LINK_NV];
    const double *p = planar_2link_parameter_defaults;
    int k, i;
    for (k = 0; k < N; ++k)
        for (i = 0; i < PLANAR_2LINK_NV; ++i) {
            q[k * PLANAR_2LINK_NV + i] = states[k][0][i];
            qd[k * PLANAR_2LINK_NV + i] = states[k][1][i];
            x[k * PLANAR_2LINK_NV + i] = states[k][2][i];
        }
    planar_2link_inverse_dynamics_batch(N, q, qd, x, p, tau);
    planar_2link_inverse_dynamics_derivatives_batch(N, q, qd, x, p, d);
    planar_2link_forward_dynamics_aba_batch(N, q, qd, x, p, qdd);
    for (k = 0; k < N; ++k) {
        for (i = 0; i < PLANAR_2LINK_NV; ++i) printf("%%.17g ", tau[k * PLANAR_2LINK_NV + i]);
        for (i = 0; i < 4 * PLANAR_2LINK_NV; ++i) printf("%%.17g ", d[k * 4 * PLANAR_2LINK_NV + i]);
        for (i = 0; i < PLANAR_2LINK_NV; ++i) printf("%%.17g ", qdd[k * PLANAR_2LINK_NV + i]);
        printf("\n");
    }
    return 0;
}
"""


@pytest.mark.skipif(c_compiler() is None, reason="needs a C compiler")
def test_kernel_batches_equal_the_numpy_module_state_by_state(tmp_path, monkeypatch):
    """``<robot>_<function>_batch`` over 11 states (two blocks of four through the lanes kernels,
    or one of eight with ``-DEOM_LANES=8``, the rest one by one) equals the NumPy module at each
    state: with the SIMD lanes (-march=native where the compiler takes it), without them
    (``<ROBOT>_NO_LANES``), eight lanes (AVX-512's width, split by the compiler where the
    machine has narrower vectors) and at plain -O2. The
    planar arm's kernels are below the size that gets lanes; the bound is lowered here so that
    every one of them has a lanes version."""
    monkeypatch.setattr(fast_backend, "LANES_OPERATIONS", 1)
    model = eomgen.load(eomgen.example_path("planar_2link"))
    for f in render_files(model, ["kernels", "numpy"], functions=FUNCTIONS):
        (tmp_path / f.name).write_text(f.content, encoding="utf-8")
    source = (tmp_path / "planar_2link_kernels.c").read_text(encoding="utf-8")
    for name in FUNCTIONS:  # every batch on lanes
        assert f"{name}_lanes(x, lanes_p, result)" in source
    numpy_module = load_module(tmp_path / "planar_2link_numpy.py", "planar_2link_numpy_b")
    rng = np.random.default_rng(7)
    states = rng.uniform(-2.0, 2.0, (11, 3, 2))
    expected = []
    for q, qd, x in states:
        dq, dqd = numpy_module.inverse_dynamics_derivatives(q, qd, x)
        expected.append(np.concatenate([numpy_module.inverse_dynamics(q, qd, x),
                                        np.hstack([dq, dqd]).ravel(),
                                        numpy_module.forward_dynamics_aba(q, qd, x)]))
    literal = ", ".join("{" + ", ".join("{" + ", ".join(repr(float(v)) for v in vector) + "}"
                                        for vector in state) + "}" for state in states)
    (tmp_path / "batch.c").write_text(BATCH_MAIN % {"states": literal}, encoding="utf-8")
    native = subprocess.run([c_compiler(), "-march=native", "-E", "-x", "c", "/dev/null"],
                            capture_output=True).returncode == 0
    builds = [["-O2"], ["-O2", "-DPLANAR_2LINK_NO_LANES"], ["-O2", "-DEOM_LANES=8"]] + (
        [["-O2", "-march=native"]] if native else [])
    for flags in builds:
        exe = tmp_path / "batch.out"
        subprocess.run([c_compiler(), "-std=c99", *flags, "-fno-math-errno", "-Wall", "-Werror",
                        "-I", str(tmp_path), str(tmp_path / "batch.c"),
                        str(tmp_path / "planar_2link_kernels.c"), "-o", str(exe), "-lm"],
                       check=True)
        out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
        got = np.array([[float(v) for v in line.split()] for line in out.splitlines()])
        np.testing.assert_allclose(got, np.array(expected), rtol=1e-13, atol=1e-13,
                                   err_msg=" ".join(flags))
