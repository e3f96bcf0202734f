"""One-state call cost of the fast module: this tree against another commit, in one run.

Usage::

    python benchmarks/call_overhead.py [--against REV] [--robot puma560_dh]
                                       [--repeats 1500] [--calls 200]

The fast module of ``--robot`` (a bundled example; default the PUMA 560 of
``eomgen/robots/puma560_dh.yaml``, 6 joints) is generated and compiled twice, from this tree
and from ``--against`` (default ``HEAD~1``; a temporary ``git worktree`` of it, generated with
its own eomgen in a subprocess), into a temporary folder. Both modules are loaded into this
process and their one-state calls (``inverse_dynamics(q, qd, qdd)``, ``mass_matrix(q)``,
``forward_dynamics(q, qd, tau)``) are timed alternately: each repeat times ``--calls`` calls of
one module then of the other, the order swapped every repeat, so that drift of the machine
falls on both. The table gives each one's median ns per call with the 10th–90th percentile
spread and the median of the per-repeat ratios (this tree / the other). Both modules' results
are checked equal first.

What it is for: issue 40 allows the value checks of the generated functions (finiteness,
types) to cost at most 5 % of a one-state call (the ratio ≤ 1.05). The load average is printed;
on a busy machine the spread says how far to trust the ratio. Exit status 0 when every ratio
is ≤ 1.05, 2 otherwise.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
TARGET = 1.05

GENERATE = """
import sys
from pathlib import Path
import eomgen
from eomgen.codegen.generate import generate
model = eomgen.load(eomgen.example_path(sys.argv[1]))
generate(model, Path(sys.argv[2]), backends=["fast"], cache=False)
"""


def build(tree: Path, robot: str, folder: Path) -> Path:
    """Generate and compile the fast module of ``robot`` with the eomgen of ``tree``."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    subprocess.run([sys.executable, "-c", GENERATE, robot, str(folder)], check=True, env=env,
                   cwd=tree, capture_output=True, text=True)
    return next(folder.glob("*_fast.*.so"))


def load(path: Path):
    """The extension module at ``path``, under its own name (its init function's), kept out
    of sys.modules so that two builds of one module load side by side."""
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
    parser.add_argument("--against", default="HEAD~1")
    parser.add_argument("--robot", default="puma560_dh")
    parser.add_argument("--repeats", type=int, default=1500)
    parser.add_argument("--calls", type=int, default=200)
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        other_tree = tmp / "other"
        subprocess.run(["git", "worktree", "add", "--detach", "-q", str(other_tree),
                        options.against], cwd=ROOT, check=True)
        try:
            here = load(build(ROOT, options.robot, tmp / "here"))
            other = load(build(other_tree, options.robot, tmp / "there"))
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(other_tree)], cwd=ROOT,
                           check=False)
        n = len(here.JOINT_NAMES)
        rng = np.random.default_rng(0)
        q, qd, qdd = rng.standard_normal((3, n))
        cases = {"inverse_dynamics": (q, qd, qdd), "mass_matrix": (q,),
                 "forward_dynamics": (q, qd, qdd)}
        for name, args in cases.items():
            np.testing.assert_array_equal(getattr(here, name)(*args), getattr(other, name)(*args))
        print(f"{options.robot} fast module, {options.repeats} alternating repeats of "
              f"{options.calls} calls; this tree against {options.against}; load average "
              f"{os.getloadavg()[0]:.2f}")
        print(f"{'function':18s} {'this tree ns':>22s} {'other ns':>22s} {'ratio':>7s}")
        met = True
        for name, args in cases.items():
            times = {"here": [], "other": []}
            for r in range(options.repeats):
                order = (("here", here), ("other", other))
                for tag, module in (order if r % 2 == 0 else order[::-1]):
                    times[tag].append(per_call(getattr(module, name), args, options.calls))
            ratios = sorted(a / b for a, b in zip(times["here"], times["other"]))
            cells = []
            for tag in ("here", "other"):
                t = sorted(times[tag])
                cells.append(f"{statistics.median(t):6.1f} ({t[len(t) // 10]:.0f}–"
                             f"{t[9 * len(t) // 10]:.0f})")
            ratio = statistics.median(ratios)
            met &= ratio <= TARGET
            print(f"{name:18s} {cells[0]:>22s} {cells[1]:>22s} {ratio:7.3f}  "
                  f"(ratio p10–p90 {ratios[len(ratios) // 10]:.3f}–"
                  f"{ratios[9 * len(ratios) // 10]:.3f})")
        print(f"target: every ratio ≤ {TARGET}: {'met' if met else 'not met'}")
        return 0 if met else 2


if __name__ == "__main__":
    sys.exit(main())
