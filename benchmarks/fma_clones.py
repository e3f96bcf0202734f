"""Whether the fast module's FMA clones pay, kernel by kernel: the Panda's module built with
them and without, in one run.

Usage::

    python benchmarks/fma_clones.py [--outputs M,tau,qdd_aba,dtau,dqdd,AB] [--repeats 200]
                                    [--calls 100] [--batch 64]

The Panda of example-robot-data (fingers locked, as benchmarks/fair_speed.py) is derived once
and its fast module emitted with every kernel of at least 1,000 operations marked
``FMA_CLONES`` (``FMA_CLONE_OPERATIONS`` patched to 1000, so that the kernels below today's
threshold are measured too); that source is then compiled twice: as emitted (``target_clones``:
the loader picks the FMA version on a CPU that has it) and with ``FMA_CLONES`` defined empty
(one plain x86-64 version). Both modules are loaded and each function's one-state call and
per-state time in a batch of ``--batch`` (the lanes kernels where the function has them) are
timed alternately, the order swapped every repeat; the table gives the medians and the median
ratio clones / plain (below 1: the clones pay). The calls' own cost (argument parsing, the
result array) is the same in both, so a difference is the kernel's.
"""

from __future__ import annotations

import argparse
import os
import statistics
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
from build_speed import load, per_call  # noqa: E402
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.codegen import make_job  # noqa: E402
from eomgen.codegen.backends import fast_backend  # noqa: E402
from eomgen.codegen.functions import derived_outputs, select_functions  # noqa: E402
from eomgen.dynamics import derive  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402

#: The line of runtime/fma_clones.c that makes the clones, and what replaces it for the plain
#: build.
CLONES = '#define FMA_CLONES __attribute__((target_clones("fma", "default")))'
PLAIN = "#define FMA_CLONES"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--outputs", default="M,tau,qdd_aba,dtau,dqdd,AB")
    parser.add_argument("--repeats", type=int, default=200)
    parser.add_argument("--calls", type=int, default=100)
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--threshold", type=int, default=1000)
    options = parser.parse_args()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf")
    model = lock_joints(model, {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02})
    functions = select_functions(options.outputs.split(","))
    job = make_job(derive(model, outputs=derived_outputs(functions), simplify=False), functions)
    fast_backend.FMA_CLONE_OPERATIONS = options.threshold
    (emitted,) = fast_backend.emit_fast(job)
    source = emitted.content
    assert source.count(CLONES) == 1
    kernels = [(s.name, s.operation_count) for s in job.specs]
    modules = {}
    with tempfile.TemporaryDirectory() as tmp:
        runtime = fast_backend.runtime_source
        for label, text in (("clones", source), ("plain", source.replace(CLONES, PLAIN))):
            start = time.perf_counter()
            # the kernel units' head is the runtime file's text: the same change there
            fast_backend.runtime_source = (runtime if label == "clones" else
                                           lambda name: runtime(name).replace(CLONES, PLAIN))
            built = fast_backend.compile_module(text, "panda_fast", kernels=kernels)
            fast_backend.runtime_source = runtime
            assert isinstance(built, bytes), built
            path = Path(tmp, label, "panda_fast" + (fast_backend.sysconfig.get_config_var(
                "EXT_SUFFIX") or ".so"))
            path.parent.mkdir()
            path.write_bytes(built)
            modules[label] = load(path)
            print(f"built {label} in {time.perf_counter() - start:.1f} s", flush=True)
    n = len(modules["clones"].JOINT_NAMES)
    rng = np.random.default_rng(0)
    one = rng.standard_normal((3, n))
    batch = rng.standard_normal((3, options.batch, n))
    operations = dict(kernels)
    print(f"\nPanda fast module ({options.outputs}): FMA clones against one plain version, "
          f"{options.repeats} alternating repeats; load average "
          + " ".join(f"{v:.2f}" for v in os.getloadavg()))
    print(f"{'function':34s} {'ops':>6s} {'one ns clones':>13s} {'plain':>7s} {'ratio':>6s} "
          f"{'batch ns/state clones':>21s} {'plain':>7s} {'ratio':>6s}")
    for name, ops in sorted(operations.items(), key=lambda item: item[1]):
        if ops < options.threshold:
            continue
        arity = 1 if name == "mass_matrix" else 3
        row = []
        for states, per in ((one, 1), (batch, options.batch)):
            args = tuple(states[:arity])
            times = {"clones": [], "plain": []}
            for r in range(options.repeats):
                order = ("clones", "plain") if r % 2 == 0 else ("plain", "clones")
                for label in order:
                    times[label].append(per_call(getattr(modules[label], name), args,
                                                 options.calls) / per)
            ratio = statistics.median(c / p for c, p in zip(times["clones"], times["plain"]))
            row += [statistics.median(times["clones"]), statistics.median(times["plain"]), ratio]
        print(f"{name:34s} {ops:6d} {row[0]:13.0f} {row[1]:7.0f} {row[2]:6.3f} "
              f"{row[3]:21.0f} {row[4]:7.0f} {row[5]:6.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
