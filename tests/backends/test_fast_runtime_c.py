"""The fast backend's fixed C runtime (templates/fast/runtime/*.c) is real C: each file compiles
on its own, with the C compiler eomgen finds, free of warnings under -Wall -Wextra -Werror, and
the generated modules hold its text (below the marker line) unchanged.

A file is compiled as one translation unit: for the call runtime, behind what a generated
module defines before it (NQ, NV, NP, MAX_IN, the parameter tables); after it, a table that takes
the address of every static function and variable it defines, so that none is unused.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from eomgen.codegen.backends.fast_backend import (RUNTIME_DIR, RUNTIME_FILES, RUNTIME_MARKER,
                                                  python_headers, runtime_source)
from eomgen.common.compiler import c_compiler
from support import ROOT

WARNINGS = ("-Wall", "-Wextra", "-Werror")

#: What a generated module defines before the runtime's text that the call runtime uses (a
#: 2-joint arm with one parameter kept symbolic, of which the description gives the value).
MODULE_CONSTANTS = """\
#include <stddef.h>
#define NQ 2
#define NV 2
#define NP 1
#define MAX_IN 3
#define MAX_LEN 2
static const char *const parameter_names[NP + 1] = {"m2", NULL};
static const double parameter_defaults[NP + 1] = {1.5, 0.0};
static const int parameter_has_default[NP + 1] = {1, 0};
static const char *const renamed_parameters[][2] = {{NULL, NULL}};
"""

#: What each runtime file needs defined before it.
PRELUDES = {"call": MODULE_CONSTANTS, "contact_call": MODULE_CONSTANTS,
            "task_call": MODULE_CONSTANTS}

#: A static function or variable defined at the start of a line of the runtime's text.
STATIC = re.compile(r"^static\s+[^;(]*?\**\b(\w+)\s*(?:\(|=|\[)", re.M)


def _toolchain() -> tuple[str, tuple[str, ...]]:
    compiler = c_compiler()
    if compiler is None:
        pytest.skip("no C compiler found ($CC, cc, gcc, clang): the runtime is not compiled")
    headers = python_headers()
    if headers is None:
        pytest.skip("Python's C headers (Python.h) are not installed")
    return compiler, headers


#: What uses the macros of a runtime file that defines no static (the files the head of a split
#: build's kernel unit is made of, issue 42): a cloned kernel; a lanes kernel taking sin, cos
#: and sqrt lane by lane, behind the call runtime's eom_lanes.
MACRO_USES = {
    "fma_clones": "\nFMA_CLONES double runtime_use(double x);\n"
                  "FMA_CLONES double runtime_use(double x) { return x * x + 1.0; }\n",
    "lanes": "\nvoid runtime_use(const eom_lanes *x, eom_lanes *out);\n"
             "void runtime_use(const eom_lanes *x, eom_lanes *out)\n"
             "{ *out = sin(*x) * cos(*x) + sqrt(*x) + EOM_BROADCAST(1.0); }\n#endif\n",
}
#: What goes before a macro file: the lanes macros need eom_lanes and the vector sin/cos
#: (lanes_math.c, which defines eom_lanes above its marker), inside #if EOM_LANES > 1.
MACRO_PRELUDES = {"lanes": f'#include "{RUNTIME_DIR / "lanes_math.c"}"\n#if EOM_LANES > 1\n'}

#: A runtime file that another includes to compile alone (kkt.c the Cholesky runtime).
INCLUDE = re.compile(r'^#include "(\w+)\.c"', re.M)


def _unit(name: str) -> str:
    """The translation unit of runtime file ``name``: prelude, the file, the statics of the
    file and of the runtime files it includes used."""
    text = (RUNTIME_DIR / f"{name}.c").read_text(encoding="utf-8")
    included = INCLUDE.findall(text.partition(RUNTIME_MARKER)[0])
    statics = [s for part in (name, *included) for s in STATIC.findall(runtime_source(part))]
    if name in MACRO_USES:
        assert not statics, name
        return (MACRO_PRELUDES.get(name, "") + f'#include "{RUNTIME_DIR / (name + ".c")}"\n'
                + MACRO_USES[name])
    assert statics, name
    used = ", ".join(f"(const void *)&{symbol}" for symbol in statics)
    return (PRELUDES.get(name, "") + f'#include "{RUNTIME_DIR / (name + ".c")}"\n'
            f"const void *const runtime_statics[] = {{{used}}};\n")


def _compile(tmp_path: Path, source: str, *extra: str, link: bool = False) -> Path:
    compiler, headers = _toolchain()
    c_path = tmp_path / "unit.c"
    c_path.write_text(source, encoding="utf-8")
    target = tmp_path / ("unit" if link else "unit.o")
    command = [compiler, *WARNINGS, *(f"-I{h}" for h in headers), *extra,
               *([] if link else ["-c"]), "-o", str(target), str(c_path),
               *(["-lm"] if link else [])]
    result = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, f"{' '.join(command)}\n{result.stderr}"
    return target


def test_every_runtime_file_has_its_marker_and_no_template_syntax():
    found = sorted(p.stem for p in RUNTIME_DIR.glob("*.c"))
    assert found == sorted(RUNTIME_FILES)
    for name in RUNTIME_FILES:
        text = (RUNTIME_DIR / f"{name}.c").read_text(encoding="utf-8")
        assert text.count(RUNTIME_MARKER) == 1, name
        body = runtime_source(name)
        assert not re.search(r"\{\{|\{%|\{#", body), name
        assert body and not body.endswith("\n"), name


@pytest.mark.parametrize("name", RUNTIME_FILES)
def test_runtime_file_compiles_alone_without_warnings(name, tmp_path):
    assert _compile(tmp_path, _unit(name)).is_file()


def test_cholesky_runtime_factors_and_solves(tmp_path):
    """L L^T = A, A x = b through solve_lower and solve_upper, and a matrix that is not
    positive definite refused (status 2), on a 3 x 3 example whose factor is exact in binary."""
    program = f'#include "{RUNTIME_DIR / "cholesky.c"}"\n' + r"""
#include <stdio.h>
int main(void)
{
    /* A = L L^T with L = [[2, 0, 0], [1, 3, 0], [-1, 2, 4]]; y = A (1, 2, 3)^T */
    double A[9] = {4, 2, -2, 2, 10, 5, -2, 5, 21};
    double y[3] = {2, 37, 71};
    double bad[4] = {1, 2, 2, 1};
    double dmax, dmin;
    int status = cholesky(A, 3, 0.0, &dmax, &dmin);
    solve_lower(A, 3, y);
    solve_upper(A, 3, y);
    printf("%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g", status,
           A[0], A[3], A[4], A[6], A[7], A[8], dmax, dmin, y[0], y[1], y[2]);
    printf(" %d\n", cholesky(bad, 2, 0.0, &dmax, &dmin));
    return 0;
}
"""
    executable = _compile(tmp_path, program, link=True)
    result = subprocess.run([str(executable)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    values = result.stdout.split()
    assert values[0] == "0" and values[-1] == "2"
    assert [float(v) for v in values[1:9]] == [2.0, 1.0, 3.0, -1.0, 2.0, 4.0, 4.0, 2.0]
    for got, expected in zip(values[9:12], (1.0, 2.0, 3.0)):
        assert abs(float(got) - expected) < 1e-14, values


def test_generated_modules_hold_the_runtime_text_and_build_false_compiles_nothing():
    """A module with forward dynamics holds the Cholesky and call runtimes, one with contacts
    the KKT runtime too, each as in its file; render_files(..., build=False) emits the C source
    without compiling it (no binary among the files, the same source as a building render)."""
    import eomgen
    from eomgen.codegen.functions import select_functions
    from eomgen.codegen.generate import render_files
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene

    arm = eomgen.load(eomgen.example_path("planar_2link"))
    wall = apply_scene(arm, load_scene(ROOT / "examples/contacts/planar_2link_wall.yaml")).model
    for model, functions, expected in (
            (arm, None, ("cholesky", "call")),
            (wall, ["constrained_forward_dynamics"], ("cholesky", "kkt", "call", "contact_call"))):
        chosen = None if functions is None else select_functions(functions)
        files = render_files(model, ["fast"], functions=chosen, build=False)
        assert [f.name for f in files] == [f"{model.name}_fast.c"]
        assert all(isinstance(f.content, str) and f.golden for f in files)
        source = files[0].content
        for name in RUNTIME_FILES:
            assert (runtime_source(name) in source) == (name in expected), (model.name, name)
        if functions is None:  # the building render writes the same text (and maybe a binary)
            built = render_files(model, ["fast"], build=True)
            assert built[0].name == files[0].name and built[0].content == source


#: The sine and cosine of the lanes kernels (runtime lanes_math.c) against libm's, in ulp of
#: libm's result: random points over |x| <= 1e3 and 1e5, the doubles nearest each multiple of
#: pi/2 up to 1e3 and their neighbours (results near 0: the reduction's accuracy), and the
#: values that go through libm lane by lane (beyond 1e5, +-inf, nan) bit for bit.
LANES_MATH_PROGRAM = r"""
#include <stdio.h>
#include <stdlib.h>
static double ulps(double got, double want)
{
    double unit = nextafter(fabs(want), INFINITY) - fabs(want);
    return fabs(got - want) / unit;
}
static double worst = 0.0;
static int mismatched = 0;
static void check(const eom_lanes *at)
{
    eom_lanes x = *at, s, c;
    int l;
    eom_sincos_lanes(&x, &s, &c);
    for (l = 0; l < EOM_LANES; ++l) {
        double e = ulps(s[l], sin(x[l])), f = ulps(c[l], cos(x[l]));
        if (isnan(x[l]) || isinf(x[l]) || fabs(x[l]) > 1e5)
            mismatched += !((isnan(s[l]) && isnan(sin(x[l]))) || s[l] == sin(x[l]));
        else {
            worst = e > worst ? e : worst;
            worst = f > worst ? f : worst;
        }
    }
}
int main(int argc, char **argv)
{
    const double range = atof(argv[1]);
    const long count = atol(argv[2]);
    unsigned long long state = 12345;
    long i;
    int k, d, l;
    (void)argc;
    for (i = 0; i < count; i += EOM_LANES) {
        eom_lanes x;
        for (l = 0; l < EOM_LANES; ++l) {
            state = state * 6364136223846793005ULL + 1442695040888963407ULL;
            x[l] = (2.0 * (double)(state >> 11) / 9007199254740992.0 - 1.0) * range;
        }
        check(&x);
    }
    for (k = -640; k <= 640; ++k)
        for (d = -3; d <= 3; ++d) {
            double y = k * 1.5707963267948966;
            eom_lanes x;
            for (l = 0; l < (d < 0 ? -d : d); ++l)
                y = nextafter(y, d < 0 ? -INFINITY : INFINITY);
            for (l = 0; l < EOM_LANES; ++l)
                x[l] = y;
            check(&x);
        }
    {
        eom_lanes far = {0.5, 2e5, -INFINITY, NAN};
        check(&far);
    }
    printf("%.3f %d\n", worst, mismatched);
    return 0;
}
"""


@pytest.mark.parametrize("fma", [False, True])
def test_lanes_sine_and_cosine_are_within_2_ulp_of_libm(tmp_path, fma):
    """At most 2 ulp from libm's sin and cos over |x| <= 1e3 (docs/numerics.md), also where
    they are near 0; libm's own values beyond 1e5 and for +-inf and nan. Both builds: plain and
    with FMA and AVX2 (the lanes kernels' FMA clone; skipped on a CPU without them)."""
    flags = ["-O2"]
    if fma:
        cpu = Path("/proc/cpuinfo")
        words = cpu.read_text().split() if cpu.is_file() else []
        if "fma" not in words or "avx2" not in words:
            pytest.skip("this CPU has no FMA and AVX2 (or no /proc/cpuinfo says so)")
        flags += ["-mfma", "-mavx2"]
    source = f'#include "{RUNTIME_DIR / "lanes_math.c"}"\n' + LANES_MATH_PROGRAM
    executable = _compile(tmp_path, source, *flags, link=True)
    for scale, count in (("1e3", 400_000), ("1e5", 100_000), ("3.2", 100_000)):
        result = subprocess.run([str(executable), scale, str(count)], capture_output=True,
                                text=True, timeout=60)
        assert result.returncode == 0, result.stderr
        worst, mismatched = result.stdout.split()
        assert float(worst) <= 2.0 and mismatched == "0", (scale, result.stdout)
