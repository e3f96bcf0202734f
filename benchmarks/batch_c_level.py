"""Batches at C level against the fast module's Python batch call (issue 43: "the Python batch
call within 1.3× of the C-level figure").

The Panda of benchmarks/batch_speed.py (fingers locked), the functions of its CASES. Two
contenders per function, on the same N random states (default 10,000), one thread:

- **C level**: the ``kernels`` backend's ``panda_<function>_batch`` (four states per SIMD
  vector where the function has a lanes kernel, the inputs transposed once per block of four),
  called from a C program on arrays already in its layout (state-major, as NumPy's (N, NV)),
  compiled with the fast module's flags plus ``-march=native`` (the fast module picks its FMA
  clone at load time on this machine: the same instructions);
- **Python**: the fast module's batch call ``fast.<function>(q, qd, ...)`` on (N, NV) arrays,
  ``set_threads(1)``: the argument parsing, the checks of the value rule, the transposes, the
  result's allocation.

Each round runs the C program once (it times every function once on the whole batch) and then
the Python calls; the figures are per state in µs, the median over ``--repeats`` rounds; the
ratio is the median of the per-round ratios Python / C. The results are first checked against
each other (1e-12 of the largest entry). The machine's load is printed with each row.

Usage::

    python benchmarks/batch_c_level.py
    python benchmarks/batch_c_level.py --markdown benchmarks/results/batch_c_level.md
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy
sys.path.insert(0, str(ROOT / "benchmarks"))

import eomgen  # noqa: E402
from batch_speed import CASES, flat, load, panda_fast  # noqa: E402
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen.backends.fast_backend import FastConfig  # noqa: E402
from eomgen.codegen.functions import select_functions  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.common.compiler import c_compiler  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from fair_speed import LOCKED  # noqa: E402

#: The C program: reads N and the inputs (q, qd, qdd, tau: N x 7 doubles each) from argv[1],
#: times each function's batch once after a first call that warms it (the result's pages
#: touched beforehand), prints "name seconds" lines and writes the results to
#: argv[2] (in CASES order).
DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "panda_kernels.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

int main(int argc, char **argv)
{
    long n;
    FILE *in = fopen(argv[1], "rb"), *out = fopen(argv[2], "wb");
    if (in == NULL || out == NULL || fread(&n, sizeof n, 1, in) != 1) return 2;
    double *data = malloc(sizeof(double) * 4 * n * PANDA_NV);
    double *result = malloc(sizeof(double) * n * %(largest)d);
    if (fread(data, sizeof(double), 4 * n * PANDA_NV, in) != (size_t)(4 * n * PANDA_NV)) return 2;
    const double *q = data, *qd = data + n * PANDA_NV, *qdd = data + 2 * n * PANDA_NV;
    const double *tau = data + 3 * n * PANDA_NV;
    const double *p = panda_parameter_defaults;
    double start;
    (void)tau; (void)qdd; (void)qd;
    memset(result, 0, sizeof(double) * n * %(largest)d);  /* its pages touched before timing */
%(calls)s
    fclose(out);
    return 0;
}
"""

CALL = r"""    panda_%(name)s_batch(n, %(inputs)s, p, result);  /* warm: code and data in cache */
    start = now();
    panda_%(name)s_batch(n, %(inputs)s, p, result);
    printf("%(name)s %%.9e\n", now() - start);
    fwrite(result, sizeof(double), n * %(size)d, out);
"""


def side_by_side(result, states: int) -> np.ndarray:
    """A batch's result as the kernels write it, one row per state: a tuple of matrices side by
    side (each state's (rows, cols₁ + cols₂ + ...) row-major), anything else flattened."""
    parts = result if isinstance(result, tuple) else (result,)
    if all(np.ndim(part) == 3 for part in parts):
        return np.concatenate(parts, axis=2).reshape(states, -1)
    return flat(result, states)


def panda_model():
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(path)
    return lock_joints(model, LOCKED)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10_000)
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--target", default="-march=native",
                        help="the C program's target flag (default -march=native; e.g. -mfma "
                        "or -mavx2 -mfma to compare with the fast module's FMA clones)")
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    args = parser.parse_args()
    compiler = c_compiler()
    if compiler is None:
        sys.exit("batch_c_level: no C compiler")
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    n = args.states
    rng = np.random.default_rng(0)
    data = {name: rng.uniform(-2.0, 2.0, (n, 7)) for name in ("q", "qd", "qdd", "tau")}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        fast = panda_fast(folder)
        fast.set_threads(1)
        files = render_files(panda_model(), ["kernels"],
                             functions=select_functions([c[1] for c in CASES]))
        for f in files:
            (folder / f.name).write_text(f.content, encoding="utf-8")
        sizes = {name: flat(getattr(fast, name)(*[data[i][:1] for i in inputs]), 1).shape[1]
                 for _, name, inputs, _ in CASES}
        calls = "".join(CALL % dict(name=name, inputs=", ".join(inputs), size=sizes[name])
                        for _, name, inputs, _ in CASES)
        (folder / "driver.c").write_text(DRIVER % dict(largest=max(sizes.values()),
                                                       calls=calls), encoding="utf-8")
        flags = [f for f in FastConfig().flags if f not in ("-shared", "-fPIC")]
        command = [compiler, *flags, *args.target.split(), "-I", str(folder),
                   str(folder / "driver.c"), str(folder / "panda_kernels.c"),
                   "-o", str(folder / "driver"), "-lm"]
        subprocess.run(command, check=True)
        inputs_path, results_path = folder / "inputs.bin", folder / "results.bin"
        with open(inputs_path, "wb") as stream:
            stream.write(np.int64(n).tobytes())
            for name in ("q", "qd", "qdd", "tau"):
                stream.write(np.ascontiguousarray(data[name]).tobytes())

        def c_round() -> dict[str, float]:
            out = subprocess.run([str(folder / "driver"), str(inputs_path), str(results_path)],
                                 check=True, capture_output=True, text=True).stdout
            return {name: float(value) / n for name, value in
                    (line.split() for line in out.splitlines())}

        c_round()
        results = np.fromfile(results_path)
        offset = 0
        for label, name, inputs, _ in CASES:
            c_result = results[offset:offset + n * sizes[name]].reshape(n, sizes[name])
            offset += n * sizes[name]
            python = side_by_side(getattr(fast, name)(*[data[i] for i in inputs]), n)
            error = np.max(np.abs(python - c_result)) / np.max(np.abs(python))
            if error > 1e-12:
                sys.exit(f"batch_c_level: {name}: C and Python batches differ by {error:.1e}")
        uptime = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
        say(f"Panda, 7 joints (fingers locked); batch of {n:,} states, 1 thread; C: "
            f"{' '.join(command[:1 + len(flags) + len(args.target.split())])} (the kernels backend); median of "
            f"{args.repeats} rounds.")
        say(f"uptime before: {uptime}")
        say()
        times: dict[str, dict[str, list[float]]] = {name: {"c": [], "python": []}
                                                     for _, name, _, _ in CASES}
        for _ in range(args.repeats):
            for name, seconds in c_round().items():
                times[name]["c"].append(seconds)
            for _, name, inputs, _ in CASES:
                batch = [data[i] for i in inputs]
                function = getattr(fast, name)
                start = time.perf_counter()
                function(*batch)
                times[name]["python"].append((time.perf_counter() - start) / n)
        say("| output | C level (kernels `_batch`) | Python batch (fast module) | Python / C | "
            "target | load (1, 5, 15 min) |")
        say("|---|---:|---:|---:|---|---|")
        for label, name, _, _ in CASES:
            c, py = times[name]["c"], times[name]["python"]
            ratio = statistics.median(b / a for a, b in zip(c, py))
            say(f"| {label} | {statistics.median(c) * 1e6:.3f} µs (spread "
                f"{min(c) * 1e6:.3f}–{max(c) * 1e6:.3f}) | {statistics.median(py) * 1e6:.3f} µs "
                f"(spread {min(py) * 1e6:.3f}–{max(py) * 1e6:.3f}) | {ratio:.2f}× | ≤ 1.3×, "
                f"{'met' if ratio <= 1.3 else 'not met'} | {load()} |")
        fast.set_threads(None)
    uptime = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    say()
    say(f"uptime after: {uptime}")
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
