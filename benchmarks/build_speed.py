"""Build time of the Panda's fast module with the derivative outputs: this tree against another
commit, in one run, and the one-state call time of the two modules.

Usage::

    python benchmarks/build_speed.py [--against main] [--jobs 1,2] [--repeats 1]
                                     [--outputs M,tau,qdd_aba,dtau,dqdd,AB] [--calls 200]

The Panda of example-robot-data with its fingers locked (as benchmarks/fair_speed.py) is
derived and its fast module built in a fresh process each time, from ``--against`` (a
``git archive`` of it in a temporary folder, with its own eomgen) and from this tree with each
``--jobs`` (issue 42: the long kernels compiled as translation units in parallel, their
objects cached by content): *cold* with an empty object cache, *warm* again with the cache that
build filled (nothing to compile: the link only), and *one more output* with the cache filled by
a build of every output but the last (what adding an output costs). Each process reports the
derivation (derive and make_job) and the fast backend's stage (render, compile, link) apart.

The table gives the median over ``--repeats`` of each, and the ratio of this tree's total to the
other's measured in the same run. Then both modules (this tree's cold build at the largest
``--jobs``) are loaded and their one-state calls timed alternately, as in
benchmarks/call_overhead.py: the median ratio per function (issue 42: no more than 1.10). The
load average (``os.getloadavg``) is printed before and after: the machine's other work falls on
both sides only roughly, since the builds run one after another.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CALL_TARGET = 1.10

#: What each build process runs: derive the locked Panda, then the fast backend; prints
#: {"derive": s, "fast": s, "stem": ...} on its last line.
BUILD = r"""
import json, sys, time, warnings
from pathlib import Path
import eomgen
from eomgen.codegen import make_job
from eomgen.codegen.generate import render_job
from eomgen.dynamics import derive
from eomgen.model import lock_joints
sys.path.insert(0, sys.argv[3])
from codegen_speed import erd_robots_dir
outputs, folder = sys.argv[1].split(","), Path(sys.argv[2])
start = time.perf_counter()
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    model = eomgen.load(erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf")
model = lock_joints(model, {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02})
from eomgen.codegen.functions import derived_outputs, select_functions
functions = select_functions(outputs)
dynamics = derive(model, outputs=derived_outputs(functions), simplify=False)
job = make_job(dynamics, functions)
derived = time.perf_counter()
files = render_job(job, ["fast"])
built = time.perf_counter()
folder.mkdir(parents=True, exist_ok=True)
for f in files:
    (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                  else f.content.encode("utf-8"))
print(json.dumps({"derive": derived - start, "fast": built - derived,
                  "functions": list(job.functions)}))
"""


def load_average() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def build(tree: Path, outputs: str, folder: Path, cache: Path, jobs: int | None) -> dict:
    """One build in a fresh process with the eomgen of ``tree``; its times and wall time."""
    env = {**os.environ, "PYTHONPATH": str(tree), "EOMGEN_CACHE_DIR": str(cache)}
    env.pop("EOMGEN_JOBS", None)
    if jobs is not None:
        env["EOMGEN_JOBS"] = str(jobs)
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-c", BUILD, outputs, str(folder),
                             str(ROOT / "benchmarks")], env=env,
                            cwd=tree, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"build_speed: the build in {tree} failed:\n{result.stderr[-3000:]}")
    times = json.loads(result.stdout.strip().splitlines()[-1])
    return {**times, "wall": wall}


def load(path: Path):
    """The extension module at ``path``, kept out of sys.modules (two builds side by side)."""
    spec = importlib.util.spec_from_file_location(path.name.split(".")[0], path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def per_call(function, args, calls: int) -> float:
    start = time.perf_counter()
    for _ in range(calls):
        function(*args)
    return (time.perf_counter() - start) / calls * 1e9


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", default="main")
    parser.add_argument("--jobs", default="1,2")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--outputs", default="M,tau,qdd_aba,dtau,dqdd,AB")
    parser.add_argument("--calls", type=int, default=200)
    parser.add_argument("--call-repeats", type=int, default=300)
    options = parser.parse_args()
    jobs = [int(j) for j in options.jobs.split(",")]
    fewer = ",".join(options.outputs.split(",")[:-1])
    print(f"build_speed: load average before {load_average()}", flush=True)
    rows: dict[str, list[dict]] = {}

    def record(label: str, times: dict) -> None:
        rows.setdefault(label, []).append(times)
        print(f"  {label}: {times['wall']:.1f} s (derive {times['derive']:.1f} s, fast "
              f"{times['fast']:.1f} s), load {load_average()}", flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        other = tmp / "other"
        other.mkdir()
        archive = subprocess.run(["git", "archive", "--format=tar", options.against],
                                 cwd=ROOT, check=True, capture_output=True).stdout
        archive_path = tmp / "other.tar"
        archive_path.write_bytes(archive)
        with tarfile.open(archive_path) as tar:
            tar.extractall(other)
        for r in range(options.repeats):
            record(f"{options.against}", build(other, options.outputs, tmp / f"other{r}",
                                               tmp / f"cache_other{r}", None))
            for j in jobs:
                cache = tmp / f"cache{r}_{j}"
                record(f"jobs={j} cold", build(ROOT, options.outputs, tmp / f"here{r}_{j}",
                                               cache, j))
                record(f"jobs={j} warm", build(ROOT, options.outputs, tmp / f"warm{r}_{j}",
                                               cache, j))
                added = tmp / f"cache_added{r}_{j}"
                build(ROOT, fewer, tmp / f"fewer{r}_{j}", added, j)
                record(f"jobs={j} one more output", build(ROOT, options.outputs,
                                                          tmp / f"added{r}_{j}", added, j))
        print(f"\nPanda (fingers locked) fast module with {options.outputs}; "
              f"{options.repeats} repeat(s); load average after {load_average()}")
        print(f"{'build':24s} {'wall s':>8s} {'derive s':>9s} {'fast s':>8s} "
              f"{'/ ' + options.against:>10s}")
        base = statistics.median(t["wall"] for t in rows[options.against])
        for label, times in rows.items():
            wall = statistics.median(t["wall"] for t in times)
            print(f"{label:24s} {wall:8.1f} "
                  f"{statistics.median(t['derive'] for t in times):9.1f} "
                  f"{statistics.median(t['fast'] for t in times):8.1f} {wall / base:10.2f}")

        here = load(next((tmp / f"here0_{max(jobs)}").glob("panda_fast.*.so")))
        there = load(next((tmp / "other0").glob("panda_fast.*.so")))
        n = len(here.JOINT_NAMES)
        rng = np.random.default_rng(0)
        q, qd, a = rng.standard_normal((3, n))
        functions = rows[f"jobs={max(jobs)} cold"][0]["functions"]
        print(f"\none-state calls, {options.call_repeats} alternating repeats of "
              f"{options.calls} calls; load average {load_average()}")
        print(f"{'function':34s} {'this tree ns':>13s} {options.against + ' ns':>13s} "
              f"{'ratio':>7s}")
        met = True
        for name in functions:
            if not hasattr(here, name):
                continue
            args = (q,) if name == "mass_matrix" else (q, qd, a)
            got, expected = getattr(here, name)(*args), getattr(there, name)(*args)
            for x, y in zip(got if isinstance(got, tuple) else (got,),
                            expected if isinstance(expected, tuple) else (expected,)):
                np.testing.assert_allclose(x, y, rtol=1e-12, atol=1e-12, err_msg=name)
            times = {"here": [], "there": []}
            for r in range(options.call_repeats):
                order = (("here", here), ("there", there))
                for tag, module in (order if r % 2 == 0 else order[::-1]):
                    times[tag].append(per_call(getattr(module, name), args, options.calls))
            ratio = statistics.median(h / t for h, t in zip(times["here"], times["there"]))
            met &= ratio <= CALL_TARGET
            print(f"{name:34s} {statistics.median(times['here']):13.0f} "
                  f"{statistics.median(times['there']):13.0f} {ratio:7.3f}")
        print(f"call target: every ratio ≤ {CALL_TARGET}: {'met' if met else 'not met'}")
        return 0 if met else 2


if __name__ == "__main__":
    sys.exit(main())
