"""eomgen's generated C kernels against Pinocchio's code-generated path and Pinocchio's plain C++,
the three in one C++ program, one state per call (issue 43): τ, M, q̈, ∂τ/∂(q, q̇), ∂q̈/∂(q, q̇, τ)
of the Panda (fingers locked).

The code-generated peer is the path Pinocchio's published code-generation figures come from
(its ``benchmark/timings-cg.cpp``): the algorithms run once on CppAD scalars whose operations
CppADCodeGen records, the recording is written out as C and compiled into a shared library, and
each call goes through the public ``evalFunction(q, v, a)`` of Pinocchio's classes
``CodeGenRNEA``, ``CodeGenCRBA``, ``CodeGenABA``, ``CodeGenRNEADerivatives`` and
``CodeGenABADerivatives`` (``pinocchio/codegen/cppadcg-algo.hpp`` in the ``pin`` wheel; CppAD and
CppADCodeGen from the ``cmeel-cppad`` and ``cmeel-cppadcodegen`` wheels, the ``bench`` extra).
Pinocchio's ``compileLib`` takes one optimisation option; here the generated C gets the same
flags as the other two (``-O3 -march=native``, set on CppADCodeGen's ``GccCompiler``), and the
classes build no Jacobian code (not timed, and the Jacobian of a derivative is second order).
``evalFunction`` copies (q, v, a) into the library's input vector and its output vector into
the class's matrices: that is the call a user makes, so it is timed as it is.

* eomgen: the ``kernels`` backend's ``panda_kernels.c`` (``extern "C"``), ``double[7]`` inputs;
* Pinocchio C++: header-only (the algorithms compiled in this translation unit), Eigen vectors;
* the model: Pinocchio's own reduced model of the URDF written out as ``addJoint`` /
  ``appendBodyToJoint`` statements (derivatives_c.py's), which every side uses.

Results are compared first, over 64 random states, the code-generated outputs against
Pinocchio's C++ and eomgen's against Pinocchio's C++ (≤ 1e-10 relative to the largest entry;
upper triangles of M and M⁻¹): the run stops on a disagreement. Timing: the process's CPU
time around loops of calls (``CLOCK_PROCESS_CPUTIME_ID``), the three contenders in turns,
``--repeats`` times; medians (min–max) in ns per call and the median of per-repeat ratios.
The compiles take minutes (the C++ program about 5 on two cores, the generated libraries
less): a benchmark, never a test.

Usage::

    python benchmarks/pinocchio_codegen.py [--repeats 15] [--markdown benchmarks/results/pinocchio_codegen.md]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
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
from derivatives_c import DEFINES, FLAGS, program  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from fair_speed import LOCKED, pinocchio_panda  # noqa: E402

FUNCTIONS = ("inverse_dynamics", "mass_matrix", "forward_dynamics_aba",
             "inverse_dynamics_derivatives", "forward_dynamics_derivatives")

MAIN = r"""
#include <pinocchio/codegen/cppadcg-algo.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <time.h>
#include <vector>
#include "panda_kernels.h"

static const int S = 64;  /* states */
static const int n = PANDA_NQ;
typedef Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> RowMajor;

/* Pinocchio's code-generation classes with what this benchmark needs opened up: the generated
   C compiled with the given flags (Pinocchio's compileLib takes one option string), no
   Jacobian code, and the results (protected in some classes) readable for the comparison. */
template <class Generator>
struct Generated : Generator {
    using Generator::Generator;
    double build(const std::string &cc, const std::vector<std::string> &flags)
    {
        auto t0 = std::chrono::steady_clock::now();
        this->build_jacobian = false;
        this->initLib();
        CppAD::cg::GccCompiler<double> compiler(cc);
        compiler.setCompileFlags(flags);
        this->dynamicLibManager_ptr->createDynamicLibrary(compiler, false);
        this->loadLib(false);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    const Eigen::VectorXd &vector() const { return this->res; }
};
struct RNEADerivatives : pinocchio::CodeGenRNEADerivatives<double> {
    using CodeGenRNEADerivatives::CodeGenRNEADerivatives;
    const Eigen::MatrixXd &dq() const { return dtau_dq; }
    const Eigen::MatrixXd &dv() const { return dtau_dv; }
};
struct ABADerivatives : pinocchio::CodeGenABADerivatives<double> {
    using CodeGenABADerivatives::CodeGenABADerivatives;
    const Eigen::MatrixXd &dq() const { return dddq_dq; }
    const Eigen::MatrixXd &dv() const { return dddq_dv; }
    const Eigen::MatrixXd &dtau() const { return dddq_dtau; }
};

@HELPERS@

static Eigen::MatrixXd upper(const Eigen::MatrixXd &m)
{
    return m.triangularView<Eigen::Upper>().toDenseMatrix();
}

int main(int argc, char **argv)
{
    int repeats = argc > 1 ? atoi(argv[1]) : 15;
    std::string cc = argc > 2 ? argv[2] : "gcc";
    std::vector<std::string> flags;
    for (int k = 3; k < argc; ++k) flags.push_back(argv[k]);
    @MODEL@
    model.name = "panda";
    pinocchio::Data data(model);
    Generated<pinocchio::CodeGenRNEA<double>> cg_rnea(model);
    Generated<pinocchio::CodeGenCRBA<double>> cg_crba(model);
    Generated<pinocchio::CodeGenABA<double>> cg_aba(model);
    Generated<RNEADerivatives> cg_drnea(model);
    Generated<ABADerivatives> cg_daba(model);
    printf("build rnea %.2f\n", cg_rnea.build(cc, flags));
    printf("build crba %.2f\n", cg_crba.build(cc, flags));
    printf("build aba %.2f\n", cg_aba.build(cc, flags));
    printf("build rnea_derivatives %.2f\n", cg_drnea.build(cc, flags));
    printf("build aba_derivatives %.2f\n", cg_daba.build(cc, flags));
    fflush(stdout);

    @STATES@
    const double *p = panda_parameter_defaults;
    double out[3 * PANDA_NQ * PANDA_NQ];
    double ours = 0.0, generated = 0.0;
    for (int s = 0; s < S; ++s) {
        const double *qs = &q[s * n], *vs = &v[s * n], *as = &a[s * n], *ts = &t[s * n];
        Eigen::VectorXd tau = pinocchio::rnea(model, data, Q[s], V[s], A[s]);
        panda_inverse_dynamics(qs, vs, as, p, out);
        cg_rnea.evalFunction(Q[s], V[s], A[s]);
        ours = std::max(ours, relative(block(out, n, 1, 0, 1), tau));
        generated = std::max(generated, relative(cg_rnea.vector(), tau));

        Eigen::MatrixXd M = upper(pinocchio::crba(model, data, Q[s]));
        panda_mass_matrix(qs, p, out);
        cg_crba.evalFunction(Q[s]);
        ours = std::max(ours, relative(upper(block(out, n, n, 0, n)), M));
        generated = std::max(generated, relative(upper(cg_crba.M), M));

        Eigen::VectorXd qdd = pinocchio::aba(model, data, Q[s], V[s], T[s]);
        panda_forward_dynamics_aba(qs, vs, ts, p, out);
        cg_aba.evalFunction(Q[s], V[s], T[s]);
        ours = std::max(ours, relative(block(out, n, 1, 0, 1), qdd));
        generated = std::max(generated, relative(cg_aba.vector(), qdd));

        pinocchio::computeRNEADerivatives(model, data, Q[s], V[s], A[s]);
        panda_inverse_dynamics_derivatives(qs, vs, as, p, out);
        cg_drnea.evalFunction(Q[s], V[s], A[s]);
        ours = std::max(ours, relative(block(out, n, 2 * n, 0, n), data.dtau_dq));
        ours = std::max(ours, relative(block(out, n, 2 * n, n, n), data.dtau_dv));
        generated = std::max(generated, relative(cg_drnea.dq(), data.dtau_dq));
        generated = std::max(generated, relative(cg_drnea.dv(), data.dtau_dv));

        pinocchio::computeABADerivatives(model, data, Q[s], V[s], T[s]);
        panda_forward_dynamics_derivatives(qs, vs, ts, p, out);
        cg_daba.evalFunction(Q[s], V[s], T[s]);
        ours = std::max(ours, relative(block(out, n, 3 * n, 0, n), data.ddq_dq));
        ours = std::max(ours, relative(block(out, n, 3 * n, n, n), data.ddq_dv));
        ours = std::max(ours, relative(upper(block(out, n, 3 * n, 2 * n, n)), upper(data.Minv)));
        generated = std::max(generated, relative(cg_daba.dq(), data.ddq_dq));
        generated = std::max(generated, relative(cg_daba.dv(), data.ddq_dv));
        generated = std::max(generated, relative(upper(cg_daba.dtau()), upper(data.Minv)));
    }
    printf("agreement %.3g %.3g\n", ours, generated);
    if (!(ours <= 1e-10 && generated <= 1e-10))
        return 1;

    double sink = 0.0;
    typedef std::function<void(int)> Call;
    struct Contest { const char *label; Call sides[3]; };
    std::vector<Contest> contests = {
        {"tau", {[&](int s) { panda_inverse_dynamics(&q[s * n], &v[s * n], &a[s * n], p, out); sink += out[0]; },
                 [&](int s) { cg_rnea.evalFunction(Q[s], V[s], A[s]); sink += cg_rnea.vector()[0]; },
                 [&](int s) { sink += pinocchio::rnea(model, data, Q[s], V[s], A[s])[0]; }}},
        {"M", {[&](int s) { panda_mass_matrix(&q[s * n], p, out); sink += out[1]; },
               [&](int s) { cg_crba.evalFunction(Q[s]); sink += cg_crba.M(0, 1); },
               [&](int s) { sink += pinocchio::crba(model, data, Q[s])(0, 1); }}},
        {"qdd", {[&](int s) { panda_forward_dynamics_aba(&q[s * n], &v[s * n], &t[s * n], p, out); sink += out[1]; },
                 [&](int s) { cg_aba.evalFunction(Q[s], V[s], T[s]); sink += cg_aba.vector()[1]; },
                 [&](int s) { sink += pinocchio::aba(model, data, Q[s], V[s], T[s])[1]; }}},
        {"dtau", {[&](int s) { panda_inverse_dynamics_derivatives(&q[s * n], &v[s * n], &a[s * n], p, out); sink += out[1]; },
                  [&](int s) { cg_drnea.evalFunction(Q[s], V[s], A[s]); sink += cg_drnea.dq()(0, 1); },
                  [&](int s) { pinocchio::computeRNEADerivatives(model, data, Q[s], V[s], A[s]); sink += data.dtau_dq(0, 1); }}},
        {"dqdd", {[&](int s) { panda_forward_dynamics_derivatives(&q[s * n], &v[s * n], &t[s * n], p, out); sink += out[1]; },
                  [&](int s) { cg_daba.evalFunction(Q[s], V[s], T[s]); sink += cg_daba.dq()(0, 1); },
                  [&](int s) { pinocchio::computeABADerivatives(model, data, Q[s], V[s], T[s]); sink += data.ddq_dq(0, 1); }}},
    };
    for (auto &contest : contests) {
        /* calls per loop: about 20 ms of the slowest side */
        int calls = 256;
        for (;;) {
            double slowest = 0.0;
            for (auto &side : contest.sides) {
                auto t0 = std::chrono::steady_clock::now();
                for (int k = 0; k < calls; ++k) side(k % S);
                slowest = std::max(slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            }
            if (slowest > 0.02) break;
            calls *= 2;
        }
        for (int r = 0; r < repeats; ++r) {
            double ns[3];
            for (int side = 0; side < 3; ++side) {
                double t0 = cpu_ns();
                for (int k = 0; k < calls; ++k) contest.sides[side](k % S);
                ns[side] = (cpu_ns() - t0) / calls;
            }
            printf("time %s %.4f %.4f %.4f\n", contest.label, ns[0], ns[1], ns[2]);
        }
    }
    printf("sink %g\n", sink);
    return 0;
}
"""

LABELS = {"tau": ("τ", "rnea"), "M": ("M", "crba"), "qdd": ("q̈", "aba"),
          "dtau": ("∂τ/∂(q, q̇)", "RNEA derivatives"), "dqdd": ("∂q̈/∂(q, q̇, τ)", "ABA derivatives")}
#: Issue 43: eomgen at most this fraction of the code-generated peer, one state per call.
TARGET = 0.7


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    parser.add_argument("--keep", type=Path, help="build in this folder and keep it (a folder "
                        "whose program is unchanged is not compiled again)")
    args = parser.parse_args()
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = lock_joints(eomgen.load(path), LOCKED)
    prefix = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
    include = prefix / "include"
    for needed, package in (("eigen3", "cmeel-eigen"), ("cppad/cg.hpp", "cmeel-cppadcodegen"),
                            ("cppad/cppad.hpp", "cmeel-cppad")):
        if not (include / needed).exists():
            sys.exit(f"pinocchio_codegen: {include / needed} not found; pip install -e .[bench] "
                     f"(it brings {package})")
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        pin, pmodel, _ = pinocchio_panda(path, model.joint_names)
        sources = {f.name: f.content for f in render_files(model, ["kernels"],
                                                           functions=FUNCTIONS)}
        sources["bench.cpp"] = program(MAIN, pmodel)
        # a kept folder whose sources are the same is not compiled again (it takes minutes)
        reuse = (folder / "bench").is_file() and all(
            (folder / name).is_file() and (folder / name).read_text(encoding="utf-8") == text
            for name, text in sources.items())
        for name, text in sources.items():
            (folder / name).write_text(text, encoding="utf-8")
        # CppADCodeGen runs the compiler by its path (execv, no PATH lookup)
        cc = shutil.which(os.environ.get("CC", "gcc")) or sys.exit("pinocchio_codegen: no C compiler")
        cxx = os.environ.get("CXX", "g++")
        start = time.perf_counter()
        subprocess.run([cc, *FLAGS, "-std=c99", "-c", "panda_kernels.c", "-o", "kernels.o"],
                       cwd=folder, check=True)
        ours_seconds = time.perf_counter() - start
        program_seconds = None
        if not reuse:
            print(f"pinocchio_codegen: compiling the C++ program (minutes) in {folder}",
                  file=sys.stderr, flush=True)
            start = time.perf_counter()
            subprocess.run([cxx, *FLAGS, "-std=c++17", "-Wno-deprecated-declarations", *DEFINES,
                            f"-I{include}", f"-I{include / 'eigen3'}", "-I.", "bench.cpp",
                            "kernels.o", "-o", "bench", "-ldl", "-lm"], cwd=folder, check=True)
            program_seconds = time.perf_counter() - start
        print("pinocchio_codegen: generating Pinocchio's libraries and timing", file=sys.stderr,
              flush=True)
        run = subprocess.run(["./bench", str(args.repeats), cc, *FLAGS], cwd=folder,
                             capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"pinocchio_codegen: the benchmark failed (exit {run.returncode}): "
                     f"{(run.stdout + run.stderr).strip()[-800:]}")
    builds, times, agreement = {}, {}, None
    for line in run.stdout.splitlines():
        parts = line.split()
        if parts[0] == "build":
            builds[parts[1]] = float(parts[2])
        elif parts[0] == "agreement":
            agreement = (float(parts[1]), float(parts[2]))
        elif parts[0] == "time":
            times.setdefault(parts[1], []).append(tuple(float(x) for x in parts[2:5]))
    lines = [
        f"Panda, 7 joints (fingers locked); Pinocchio {pin.__version__}; every side compiled with "
        f"{cc}/{cxx} {' '.join(FLAGS)}; load average {load[0]:.1f} at the start.",
        f"Compile: eomgen's kernels {ours_seconds:.1f} s (derivation and generation not included); "
        f"Pinocchio's code generation and compile of its five libraries "
        + ", ".join(f"{k} {v:.1f} s" for k, v in builds.items())
        + (f" (the C++ program holding the three: {program_seconds:.0f} s)." if program_seconds
           else " (the C++ program reused from the kept folder)."),
        f"Agreement with Pinocchio's C++ over 64 states (max relative): eomgen {agreement[0]:.1e}, "
        f"code-generated {agreement[1]:.1e}.", "",
        f"ns per call: median (min–max) over {args.repeats} repeats, the three in turns; "
        "ratio = median of per-repeat ratios.", "",
        "| output | eomgen C kernel | Pinocchio code-generated | Pinocchio C++ | eomgen / code-generated "
        "| target | met | eomgen / C++ |",
        "|---|---:|---:|---:|---:|---:|---|---:|"]

    def spread(values):
        return f"{statistics.median(values):.0f} ({min(values):.0f}–{max(values):.0f})"

    for key, samples in times.items():
        columns = list(zip(*samples))
        to_generated = statistics.median(s[0] / s[1] for s in samples)
        to_cpp = statistics.median(s[0] / s[2] for s in samples)
        label, name = LABELS[key]
        lines.append(f"| {label} | {spread(columns[0])} | {spread(columns[1])} (`{name}`) | "
                     f"{spread(columns[2])} | {to_generated:.2f} | ≤ {TARGET:.2f} | "
                     f"{'yes' if to_generated <= TARGET else 'NO'} | {to_cpp:.2f} |")
    print("\n".join(lines))
    if args.markdown:
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
