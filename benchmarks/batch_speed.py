"""Batches through the fast module: one call per state, the batch on one thread, on two (issue 43).

The Panda of benchmarks/fair_speed.py (fingers locked 2 cm open), its fast module generated with
τ (``inverse_dynamics``), M (``mass_matrix``), q̈ by the articulated-body algorithm
(``forward_dynamics_aba``), ∂τ (``inverse_dynamics_derivatives``) and ∂q̈
(``forward_dynamics_derivatives``). For each, on a batch of N random states (default 10,000):

- one call per state: a Python loop calling the function on each state (the one-state C
  kernel plus the call's parsing), on the first ``--single`` states;
- the batch on 1 thread (``set_threads(1)``): the lanes kernel, four states per SIMD vector;
- the batch on 2 threads (``set_threads(2)``).

Each time is per state, in µs, the median over ``--repeats`` rounds, the three contenders timed
in turns within each round (so that a change of the machine's load falls on all three); the
ratio 1 thread / 2 threads is the median of the per-round ratios. The clock is the wall clock
(threads: process CPU time would add theirs up); the batch on one thread is also timed in CPU
time (``time.process_time``, which waiting for a core does not inflate), and the targets are
judged on it. The machine's load (``os.getloadavg``) is printed with each row: on a shared
machine, a second thread only pays when a core is free.
The batch results are first checked against the one-call-per-state results (1e-12 of the
largest entry) and 1 thread against 2 (bitwise).

A second table checks the runtime's threshold: τ (598 operations per state) on batches of 64 ...
16,384 states, 1 thread against 2. The runtime keeps a batch on one thread below
``EOM_WORK_PER_THREAD`` (400,000) operations per thread, so up to 1,337 states both columns are
one thread; from 2,048 on the second thread runs, and its ratio says whether the threshold is
where a second thread starts to pay.

Usage::

    python benchmarks/batch_speed.py                 # a few minutes: most of it the compile
    python benchmarks/batch_speed.py --quick
    python benchmarks/batch_speed.py --markdown benchmarks/results/batch_speed.md
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
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
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen.functions import select_functions  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from fair_speed import LOCKED  # noqa: E402

#: (label, function, its inputs, target µs per state on one thread; issue 43)
CASES = (("τ", "inverse_dynamics", ("q", "qd", "qdd"), 0.06),
         ("M", "mass_matrix", ("q",), 0.07),
         ("q̈ (ABA)", "forward_dynamics_aba", ("q", "qd", "tau"), 0.15),
         ("∂τ", "inverse_dynamics_derivatives", ("q", "qd", "qdd"), 0.35),
         ("∂q̈", "forward_dynamics_derivatives", ("q", "qd", "tau"), 0.6))


def panda_fast(folder: Path):
    """The Panda's fast module with the functions of CASES, compiled into ``folder``."""
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(path)
    model = lock_joints(model, LOCKED)
    files = render_files(model, ["fast"], functions=select_functions([c[1] for c in CASES]))
    for f in files:
        (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                      else f.content.encode("utf-8"))
    libraries = [folder / f.name for f in files if not f.name.endswith(".c")]
    if not libraries:
        sys.exit("batch_speed: the fast module was not compiled (no C compiler or Python.h)")
    spec = importlib.util.spec_from_file_location("panda_fast", libraries[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def flat(result, states):
    parts = result if isinstance(result, tuple) else (result,)
    return np.concatenate([np.reshape(p, (states, -1)) for p in parts], axis=1)


def load() -> str:
    return "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def timed(call) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def cpu_timed(call) -> float:
    start = time.process_time()
    call()
    return time.process_time() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10_000)
    parser.add_argument("--single", type=int, default=2_000,
                        help="states timed one call each (default 2,000)")
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--quick", action="store_true", help="5 repeats, 500 single calls")
    parser.add_argument("--markdown", type=Path, help="also write the tables to this file")
    args = parser.parse_args()
    if args.quick:
        args.repeats, args.single = 5, 500
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        fast = panda_fast(Path(tmp))
        built = time.perf_counter() - start
    uptime = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    say(f"Panda, 7 joints (fingers locked); batch of {args.states:,} states; Python "
        f"{platform.python_version()}, NumPy {np.__version__}, {os.cpu_count()} CPUs "
        f"(this process may use {fast.threads()}); module generated and compiled in "
        f"{built:.0f} s.")
    say(f"uptime before: {uptime}")
    say()
    rng = np.random.default_rng(0)
    n = args.states
    data = {name: rng.uniform(-2.0, 2.0, (n, 7)) for name in ("q", "qd", "qdd", "tau")}
    say("| output | one call per state | batch, 1 thread | 1 thread, CPU time | batch, 2 "
        "threads | 1 / 2 threads | target (1 thread, CPU time) | load (1, 5, 15 min) |")
    say("|---|---:|---:|---:|---:|---:|---:|---|")
    for label, name, inputs, target in CASES:
        function = getattr(fast, name)
        batch = [data[i] for i in inputs]
        single = [[x[k] for x in batch] for k in range(args.single)]
        fast.set_threads(1)
        one = flat(function(*batch), n)
        fast.set_threads(2)
        two = flat(function(*batch), n)
        if one.tobytes() != two.tobytes():
            sys.exit(f"batch_speed: {name} differs between 1 and 2 threads")
        each = np.array([flat(function(*s), 1)[0] for s in single])
        error = np.max(np.abs(each - one[:args.single])) / np.max(np.abs(each))
        if error > 1e-12:
            sys.exit(f"batch_speed: {name}: batch and one call per state differ by {error:.1e}")
        times = {"single": [], 1: [], 2: [], "cpu": []}
        for _ in range(args.repeats):
            times["single"].append(timed(lambda: [function(*s) for s in single]) / args.single)
            for threads in (1, 2):
                fast.set_threads(threads)
                times[threads].append(timed(lambda: function(*batch)) / n)
            fast.set_threads(1)
            times["cpu"].append(cpu_timed(lambda: function(*batch)) / n)
        ratio = statistics.median(a / b for a, b in zip(times[1], times[2]))
        us = {key: statistics.median(value) * 1e6 for key, value in times.items()}
        say(f"| {label} | {us['single']:.3f} µs | {us[1]:.3f} µs | {us['cpu']:.3f} µs | "
            f"{us[2]:.3f} µs | {ratio:.2f}× | ≤ {target} µs, "
            f"{'met' if us['cpu'] <= target else 'not met'} | {load()} |")
    fast.set_threads(None)

    say()
    say("Where a second thread pays: τ per state (µs), 1 thread against 2, by batch size "
        "(the runtime keeps batches under EOM_WORK_PER_THREAD operations per thread on one).")
    say()
    say("| states | 1 thread | 2 threads | 1 / 2 threads | load |")
    say("|---:|---:|---:|---:|---|")
    for states in (64, 256, 1024, 2048, 4096, 16384):
        batch = [data[i][:states] for i in ("q", "qd", "qdd")]
        rounds = max(args.repeats, 20_000 // states)
        times = {1: [], 2: []}
        for _ in range(rounds):
            for threads in (1, 2):
                fast.set_threads(threads)
                times[threads].append(timed(lambda: fast.inverse_dynamics(*batch)) / states)
        ratio = statistics.median(a / b for a, b in zip(times[1], times[2]))
        say(f"| {states:,} | {statistics.median(times[1]) * 1e6:.3f} | "
            f"{statistics.median(times[2]) * 1e6:.3f} | {ratio:.2f}× | {load()} |")
    fast.set_threads(None)
    uptime = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    say()
    say(f"uptime after: {uptime}")
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
