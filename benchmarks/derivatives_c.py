"""eomgen's generated C kernels against Pinocchio's C++, both called from C++ (issue 25; Panda,
fingers locked): τ, M, C, g, q̈ and the derivatives of τ and q̈ (and of g).

Both sides are compiled here with the same compiler and flags (``-O3 -march=native``):

* ours: the ``kernels`` backend's ``panda_kernels.c`` (the fast module's arithmetic as plain C
  functions; its header is ``extern "C"``);
* Pinocchio: header-only from the ``pin`` wheel's headers (no
  ``PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION``: the algorithms are compiled in this translation
  unit), Eigen from ``cmeel-eigen``; the model built by ``addJoint``/``appendBodyToJoint`` with
  the numbers of Pinocchio's own reduced model of the URDF (fair_speed.py's), written out.

Each call works on data already in its layout (Eigen vectors for Pinocchio, ``double[7]`` for
ours), over 64 random states in turn. Timing: the process's CPU time
(``CLOCK_PROCESS_CPUTIME_ID``, which waiting for a CPU on a shared machine does not inflate)
around loops of calls, both sides in turns, ``--repeats`` times; the table shows medians (min–max) in ns per
call and the median of per-repeat ratios. Results are compared first (≤ 1e-10 relative to the
largest entry; upper triangles where Pinocchio fills only those: M of crba, M⁻¹ of the ABA
derivatives). Compiling Pinocchio takes minutes on two cores: a benchmark, never a test.
Targets: ∂τ/∂(q, q̇) ≤ 0.5 × computeRNEADerivatives, ∂q̈/∂(q, q̇, τ) ≤ 0.5 × computeABADerivatives.
(Linking the wheel's precompiled ``libpinocchio_default`` instead, with
``PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION``, built but aborted at run time with
``boost::bad_get`` here: an ABI mismatch with these flags or this Eigen, so header-only it is.)

Usage::

    python benchmarks/derivatives_c.py [--repeats 15] [--markdown benchmarks/results/derivatives_c.md]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import sysconfig
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import eomgen  # noqa: E402
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from fair_speed import LOCKED, pinocchio_panda  # noqa: E402

FUNCTIONS = ("inverse_dynamics", "mass_matrix", "coriolis_matrix", "gravity_vector",
             "forward_dynamics_aba", "inverse_dynamics_derivatives",
             "forward_dynamics_derivatives", "gravity_derivative")
DEFINES = ["-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
           "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12"]
FLAGS = ["-O3", "-march=native", "-DNDEBUG"]
JOINTS = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelPX", "JointModelPY",
          "JointModelPZ"}


def _numbers(values) -> str:
    return ", ".join(repr(float(v)) for v in values)


def model_source(model) -> str:
    """C++ statements building ``model`` (a pinocchio.Model of revolute/prismatic axis joints)."""
    lines = ["pinocchio::Model model;", "pinocchio::Model::JointIndex id;"]
    for j in range(1, model.njoints):
        kind = model.joints[j].shortname()
        if kind not in JOINTS:
            sys.exit(f"derivatives_c: joint type {kind} not written out")
        M = model.jointPlacements[j]
        Y = model.inertias[j]
        lines += [
            "{ Eigen::Matrix3d R; R << " + _numbers(M.rotation.ravel()) + ";",
            f"  id = model.addJoint({model.parents[j]}, pinocchio::{kind}(), pinocchio::SE3(R, "
            f"Eigen::Vector3d({_numbers(M.translation)})), \"{model.names[j]}\");",
            "  Eigen::Matrix3d I; I << " + _numbers(Y.inertia.ravel()) + ";",
            f"  model.appendBodyToJoint(id, pinocchio::Inertia({float(Y.mass)!r}, "
            f"Eigen::Vector3d({_numbers(Y.lever)}), I), pinocchio::SE3::Identity()); }}"]
    lines.append(f"model.gravity.linear(Eigen::Vector3d({_numbers(model.gravity.linear)}));")
    return "\n    ".join(lines)


#: C++ shared by the C-level benchmarks (here and pinocchio_codegen.py): the process's CPU time,
#: the largest entry of a difference relative to the reference's, a block of a row-major result.
CPP_HELPERS = r"""/* the process's CPU time [ns]: waiting for a CPU on a shared machine does not count */
static double cpu_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec * 1e9 + t.tv_nsec;
}

static double relative(const Eigen::MatrixXd &ours, const Eigen::MatrixXd &theirs)
{
    return (ours - theirs).cwiseAbs().maxCoeff() / theirs.cwiseAbs().maxCoeff();
}

static Eigen::MatrixXd block(const double *out, int rows, int cols, int start, int width)
{
    Eigen::Map<const RowMajor> full(out, rows, cols);
    return full.block(0, start, rows, width);
}"""

#: C++ statements drawing the S random states (q, v, a in [-1.5, 1.5], tau = rnea) both as Eigen
#: vectors (Q, V, A, T) and as plain arrays (q, v, a, t), for the benchmarks' programs.
CPP_STATES = r"""std::mt19937 rng(0);
    std::uniform_real_distribution<double> U(-1.5, 1.5);
    std::vector<Eigen::VectorXd> Q(S), V(S), A(S), T(S);
    std::vector<double> q(S * n), v(S * n), a(S * n), t(S * n);
    for (int s = 0; s < S; ++s) {
        Q[s].resize(n); V[s].resize(n); A[s].resize(n);
        for (int k = 0; k < n; ++k) {
            q[s * n + k] = Q[s][k] = U(rng); v[s * n + k] = V[s][k] = U(rng);
            a[s * n + k] = A[s][k] = U(rng);
        }
        T[s] = pinocchio::rnea(model, data, Q[s], V[s], A[s]);
        for (int k = 0; k < n; ++k) t[s * n + k] = T[s][k];
    }"""


def program(main: str, model) -> str:
    """The C++ program ``main`` with its placeholders filled: the model's statements, the
    helpers and the states."""
    return (main.replace("@HELPERS@", CPP_HELPERS).replace("@STATES@", CPP_STATES)
            .replace("@MODEL@", model_source(model)))


MAIN = r"""
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <algorithm>
#include <chrono>
#include <time.h>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>
#include "panda_kernels.h"

static const int S = 64;  /* states */
static const int n = PANDA_NQ;
typedef Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> RowMajor;

@HELPERS@

int main(int argc, char **argv)
{
    int repeats = argc > 1 ? atoi(argv[1]) : 15;
    @MODEL@
    pinocchio::Data data(model);
    @STATES@
    const double *p = panda_parameter_defaults;
    double out[3 * PANDA_NQ * PANDA_NQ];
    double worst = 0.0;
    /* agreement on every state */
    for (int s = 0; s < S; ++s) {
        const double *qs = &q[s * n], *vs = &v[s * n], *as = &a[s * n], *ts = &t[s * n];
        panda_inverse_dynamics(qs, vs, as, p, out);
        worst = std::max(worst, relative(block(out, n, 1, 0, 1), pinocchio::rnea(model, data, Q[s], V[s], A[s])));
        panda_mass_matrix(qs, p, out);
        pinocchio::crba(model, data, Q[s]);
        worst = std::max(worst, relative(block(out, n, n, 0, n).triangularView<Eigen::Upper>().toDenseMatrix(), data.M.triangularView<Eigen::Upper>().toDenseMatrix()));
        panda_coriolis_matrix(qs, vs, p, out);
        worst = std::max(worst, relative(block(out, n, n, 0, n), pinocchio::computeCoriolisMatrix(model, data, Q[s], V[s])));
        panda_gravity_vector(qs, p, out);
        worst = std::max(worst, relative(block(out, n, 1, 0, 1), pinocchio::computeGeneralizedGravity(model, data, Q[s])));
        panda_forward_dynamics_aba(qs, vs, ts, p, out);
        worst = std::max(worst, relative(block(out, n, 1, 0, 1), pinocchio::aba(model, data, Q[s], V[s], T[s])));
        panda_inverse_dynamics_derivatives(qs, vs, as, p, out);
        pinocchio::computeRNEADerivatives(model, data, Q[s], V[s], A[s]);
        worst = std::max(worst, relative(block(out, n, 2 * n, 0, n), data.dtau_dq));
        worst = std::max(worst, relative(block(out, n, 2 * n, n, n), data.dtau_dv));
        panda_forward_dynamics_derivatives(qs, vs, ts, p, out);
        pinocchio::computeABADerivatives(model, data, Q[s], V[s], T[s]);
        worst = std::max(worst, relative(block(out, n, 3 * n, 0, n), data.ddq_dq));
        worst = std::max(worst, relative(block(out, n, 3 * n, n, n), data.ddq_dv));
        worst = std::max(worst, relative(block(out, n, 3 * n, 2 * n, n).triangularView<Eigen::Upper>().toDenseMatrix(), data.Minv.triangularView<Eigen::Upper>().toDenseMatrix()));
        panda_gravity_derivative(qs, p, out);
        Eigen::MatrixXd dg = Eigen::MatrixXd::Zero(n, n);
        pinocchio::computeGeneralizedGravityDerivatives(model, data, Q[s], dg);
        worst = std::max(worst, relative(block(out, n, n, 0, n), dg));
    }
    printf("agreement %.3g\n", worst);
    if (!(worst <= 1e-10))
        return 1;
    Eigen::MatrixXd dg(n, n), C(n, n);
    Eigen::VectorXd x(n);
    double sink = 0.0;
    typedef std::function<void(int)> Call;
    struct Pair { const char *label; Call ours, theirs; };
    std::vector<Pair> pairs = {
        {"tau", [&](int s) { panda_inverse_dynamics(&q[s * n], &v[s * n], &a[s * n], p, out); sink += out[0]; },
                [&](int s) { sink += pinocchio::rnea(model, data, Q[s], V[s], A[s])[0]; }},
        {"M", [&](int s) { panda_mass_matrix(&q[s * n], p, out); sink += out[1]; },
              [&](int s) { sink += pinocchio::crba(model, data, Q[s])(0, 1); }},
        {"C", [&](int s) { panda_coriolis_matrix(&q[s * n], &v[s * n], p, out); sink += out[1]; },
              [&](int s) { sink += pinocchio::computeCoriolisMatrix(model, data, Q[s], V[s])(0, 1); }},
        {"g", [&](int s) { panda_gravity_vector(&q[s * n], p, out); sink += out[1]; },
              [&](int s) { sink += pinocchio::computeGeneralizedGravity(model, data, Q[s])[1]; }},
        {"qdd", [&](int s) { panda_forward_dynamics_aba(&q[s * n], &v[s * n], &t[s * n], p, out); sink += out[1]; },
                [&](int s) { sink += pinocchio::aba(model, data, Q[s], V[s], T[s])[1]; }},
        {"dtau", [&](int s) { panda_inverse_dynamics_derivatives(&q[s * n], &v[s * n], &a[s * n], p, out); sink += out[1]; },
                 [&](int s) { pinocchio::computeRNEADerivatives(model, data, Q[s], V[s], A[s]); sink += data.dtau_dq(0, 1); }},
        {"dqdd", [&](int s) { panda_forward_dynamics_derivatives(&q[s * n], &v[s * n], &t[s * n], p, out); sink += out[1]; },
                 [&](int s) { pinocchio::computeABADerivatives(model, data, Q[s], V[s], T[s]); sink += data.ddq_dq(0, 1); }},
        {"dg", [&](int s) { panda_gravity_derivative(&q[s * n], p, out); sink += out[1]; },
               [&](int s) { pinocchio::computeGeneralizedGravityDerivatives(model, data, Q[s], dg); sink += dg(0, 1); }},
    };
    for (auto &pair : pairs) {
        /* calls per loop: about 20 ms of the slower side */
        int calls = 256;
        for (;;) {
            auto t0 = std::chrono::steady_clock::now();
            for (int k = 0; k < calls; ++k) pair.theirs(k % S);
            double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (seconds > 0.02) break;
            calls *= 2;
        }
        for (int r = 0; r < repeats; ++r) {
            double ns[2];
            Call *sides[2] = {&pair.ours, &pair.theirs};
            for (int side = 0; side < 2; ++side) {
                double t0 = cpu_ns();
                for (int k = 0; k < calls; ++k) (*sides[side])(k % S);
                ns[side] = (cpu_ns() - t0) / calls;
            }
            printf("time %s %.4f %.4f\n", pair.label, ns[0], ns[1]);
        }
    }
    printf("sink %g\n", sink);
    return 0;
}
"""

LABELS = {"tau": ("τ", "rnea"), "M": ("M", "crba"), "C": ("C", "computeCoriolisMatrix"),
          "g": ("g", "computeGeneralizedGravity"), "qdd": ("q̈", "aba (vs our ABA program)"),
          "dtau": ("∂τ/∂(q, q̇)", "computeRNEADerivatives"),
          "dqdd": ("∂q̈/∂(q, q̇, τ)", "computeABADerivatives"),
          "dg": ("∂g/∂q", "computeGeneralizedGravityDerivatives")}
TARGETS = {"dtau": 0.5, "dqdd": 0.5}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    parser.add_argument("--keep", type=Path, help="build in this folder and keep it")
    args = parser.parse_args()
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = lock_joints(eomgen.load(path), LOCKED)
    prefix = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
    if not (prefix / "include" / "eigen3").is_dir():
        sys.exit("derivatives_c: Eigen not found; pip install cmeel-eigen")
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        for f in render_files(model, ["kernels"], functions=FUNCTIONS):
            (folder / f.name).write_text(f.content, encoding="utf-8")
        pin, pmodel, _ = pinocchio_panda(path, model.joint_names)
        (folder / "bench.cpp").write_text(program(MAIN, pmodel),
                                          encoding="utf-8")
        cc, cxx = os.environ.get("CC", "gcc"), os.environ.get("CXX", "g++")
        start = time.perf_counter()
        subprocess.run([cc, *FLAGS, "-std=c99", "-c", "panda_kernels.c", "-o", "kernels.o"],
                       cwd=folder, check=True)
        ours_seconds = time.perf_counter() - start
        include = prefix / "include"
        start = time.perf_counter()
        subprocess.run([cxx, *FLAGS, "-std=c++17", *DEFINES, f"-I{include}",
                        f"-I{include / 'eigen3'}", "-I.", "bench.cpp", "kernels.o", "-o", "bench",
                        "-lm"], cwd=folder, check=True)
        pin_seconds = time.perf_counter() - start
        run = subprocess.run(["./bench", str(args.repeats)], cwd=folder, check=True,
                             capture_output=True, text=True).stdout
    import statistics

    times: dict[str, list[tuple[float, float]]] = {}
    lines = [f"Panda, 7 joints (fingers locked); Pinocchio {pin.__version__} header-only, "
             f"{cxx} {' '.join(FLAGS)}; compile: ours {ours_seconds:.1f} s, the benchmark with "
             f"Pinocchio {pin_seconds:.0f} s.", ""]
    for line in run.splitlines():
        parts = line.split()
        if parts[0] == "agreement":
            lines.append(f"Agreement with Pinocchio over 64 states: {float(parts[1]):.1e} "
                         "(max relative).")
        elif parts[0] == "time":
            times.setdefault(parts[1], []).append((float(parts[2]), float(parts[3])))
    lines += ["", f"ns per call: median (min–max) over {args.repeats} repeats; ratio = median of "
              "per-repeat ratios.", "",
              "| output | eomgen C kernel | Pinocchio C++ | ours / Pinocchio | target | met |",
              "|---|---:|---:|---:|---:|---|"]

    def spread(values):
        return f"{statistics.median(values):.0f} ({min(values):.0f}–{max(values):.0f})"

    for key, samples in times.items():
        ours, theirs = [s[0] for s in samples], [s[1] for s in samples]
        ratio = statistics.median(a / b for a, b in samples)
        label, name = LABELS[key]
        target = TARGETS.get(key)
        lines.append(f"| {label} | {spread(ours)} | {spread(theirs)} (`{name}`) | {ratio:.2f} | "
                     + (f"≤ {target:.2f} | {'yes' if ratio <= target else 'NO'} |" if target
                        else "| |"))
    print("\n".join(lines))
    if args.markdown:
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
