"""A workspace study with the generated derivatives on a dask cluster (issue 25; Franka Panda,
fingers locked).

The statistic: over N random states (q, q̇, q̈ uniform in [−1.5, 1.5] per joint, drawn lazily
chunk by chunk where the chunk is evaluated), the largest |∂τ_i/∂q_j| of each entry, a 7 × 7 table of the arm's
worst-case torque sensitivity to its joint angles (N m/rad). ∂τ/∂q comes from the Panda's fast
module (``inverse_dynamics_derivative_q``, the loop over a block of states in C) through
``eomgen.analysis.batch.dask_map`` with ``statistic=``: each chunk is evaluated 4,096 states at a time
and reduced where it runs, so only a 7 × 7 table per chunk leaves it (never the chunk's 98 MB of
matrices); dask reduces the tables.

The same graph (same chunks, same seeds, so the same numbers and the same table, checked) is
computed three ways, in turns, wall clock (parallel speed-up is a wall-clock matter):

* one process: dask's synchronous scheduler in this process (no workers, no pickling);
* a LocalCluster of 1 worker process (1 thread): the cluster's own overhead;
  (the workers run with glibc's default memory trimming, not dask's MALLOC_TRIM_THRESHOLD_,
  which costs a compute-bound chunk half as much time again; see main());
* a LocalCluster of 2 worker processes (1 thread each): issue 25's target is
  one process / 2 workers ≥ 1.6 for N = 10⁷.

Times are medians over the repeats with the spread (min–max); the load average of the machine
before and after is printed (on a shared machine, the other processes take cores away from the
2 workers). The cluster and its dashboard listen on 127.0.0.1 only (a free port). Nothing asserts on a
time.

Usage::

    python benchmarks/derivatives_dask.py                    # 10⁷ states, a few minutes
    python benchmarks/derivatives_dask.py --states 1000000 --repeats 2
    python benchmarks/derivatives_dask.py --markdown benchmarks/results/derivatives_dask.md
"""

from __future__ import annotations

import argparse
import os
import platform
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
from codegen_speed import erd_robots_dir  # noqa: E402
from eomgen.analysis.batch import dask_map  # noqa: E402
from eomgen.codegen.generate import render_files  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402
from fair_speed import LOCKED, spread  # noqa: E402

FUNCTION = "inverse_dynamics_derivative_q"

# What a compute-bound cluster does not need, set in this process and passed by the nannies to
# the workers: the statistical profiler (it samples a working thread's stack every 10 ms) and
# the event loops' 20 ms tick and 100 ms / 500 ms monitors. Measured on this 2-core machine, an
# idle 2-worker cluster took 11.5 % of a core with dask's defaults and 1.8 % with these; one
# worker's throughput of this study rose from 1.06 to 1.12 million states/s.
QUIET = {"distributed.worker.profile.enabled": False,
         "distributed.admin.tick.interval": "500ms",
         "distributed.admin.system-monitor.interval": "2s",
         "distributed.worker.memory.monitor-interval": "1s"}


def build_module(folder: Path) -> None:
    """Write and compile the Panda's fast module with ∂τ/∂q into ``folder``."""
    path = erd_robots_dir() / "panda_description" / "urdf" / "panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = lock_joints(eomgen.load(path), LOCKED)
    for f in render_files(model, ["fast"], functions=(FUNCTION,)):
        (folder / f.name).write_bytes(f.content if isinstance(f.content, bytes)
                                      else f.content.encode("utf-8"))


def statistic(function, states: int, chunks: int):
    """The lazy 7 × 7 table max |∂τ/∂q| over ``states`` random states."""
    import dask.array as da

    sizes = (chunks,) * (states // chunks) + ((states % chunks,) if states % chunks else ())
    Q, QD, QDD = (da.map_blocks(draw, stream, chunks=(sizes, (7,)), dtype=float,
                                meta=np.empty((0, 7))) for stream in range(3))
    return dask_map(function, Q, QD, QDD, statistic=largest).max(axis=0)


def draw(stream: int, block_id=None, block_info=None) -> np.ndarray:
    """One chunk of states uniform in [−1.5, 1.5], from a generator seeded by (stream, chunk):
    the same numbers whichever process draws them. Drawn blockwise (``map_blocks``), so that
    dask fuses the drawing into the chunk's evaluation: one task per chunk, no state array
    stored or moved between workers (``dask.array.random`` arrays would be separate tasks)."""
    rng = np.random.default_rng([0, stream, block_id[0]])
    return rng.uniform(-1.5, 1.5, size=(block_info[None]["chunk-shape"][0], 7))


def largest(results: np.ndarray) -> np.ndarray:
    """max |entry| over the states (axis 0): the per-chunk statistic, reduced on the worker."""
    return np.abs(results).max(axis=0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10_000_000)
    parser.add_argument("--chunks", type=int, default=500_000, help="states per chunk")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--dask-defaults", action="store_true",
                        help="keep dask's profiler and its 20 ms / 100 ms monitors in the workers")
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    args = parser.parse_args()
    import dask
    from dask.distributed import Client, LocalCluster

    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    with tempfile.TemporaryDirectory() as tmp:
        build_module(Path(tmp))
        # the workers import the module by name (the function is pickled by reference)
        sys.path.insert(0, tmp)
        os.environ["PYTHONPATH"] = os.pathsep.join(
            [tmp, str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                                if p])
        import panda_fast

        function = getattr(panda_fast, FUNCTION)
        graph = statistic(function, args.states, args.chunks)
        # dask starts its workers with MALLOC_TRIM_THRESHOLD_=65536 (memory back to the OS
        # soon); glibc then maps every block's result arrays afresh, which made each chunk
        # 1.5x slower than in this process (4.0 against 6.2 s for 4·10⁶ states). The workers
        # here keep glibc's default, as this process has.
        environment = dict(dask.config.get("distributed.nanny.pre-spawn-environ"))
        environment.pop("MALLOC_TRIM_THRESHOLD_", None)
        dask.config.set({"distributed.nanny.pre-spawn-environ": environment})
        if not args.dask_defaults:
            dask.config.set(QUIET)
        clusters = {n: LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                    host="127.0.0.1", dashboard_address="127.0.0.1:0")
                    for n in (1, 2)}
        clients = {n: Client(cluster, set_as_default=False) for n, cluster in clusters.items()}
        try:
            cpu: list = []  # the one process's CPU seconds (its share of a core, if busy)

            def run(way):
                start, start_cpu = time.perf_counter(), time.process_time()
                if way == "one process":
                    table = graph.compute(scheduler="synchronous")
                    cpu.append(time.process_time() - start_cpu)
                else:
                    table = clients[way].compute(graph).result()
                return time.perf_counter() - start, np.asarray(table)

            ways = ("one process", 1, 2)
            load_before = os.getloadavg()
            reference = run("one process")[1]  # also warms the module and the workers up
            for n in (1, 2):
                if not np.array_equal(run(n)[1], reference):
                    sys.exit(f"derivatives_dask: the {n}-worker table differs")
            times: dict = {way: [] for way in ways}
            for _ in range(args.repeats):
                for way in ways:
                    seconds, table = run(way)
                    if not np.array_equal(table, reference):
                        sys.exit(f"derivatives_dask: the table of {way} differs")
                    times[way].append(seconds)
            load_after = os.getloadavg()
        finally:
            for client in clients.values():
                client.close()
            for cluster in clusters.values():
                cluster.close()

    one = statistics.median(times["one process"])
    say(f"Panda, 7 joints (fingers locked): max |dtau/dq| over {args.states:,} random states in "
        f"chunks of {args.chunks:,}; Python {platform.python_version()}, dask "
        f"{dask.__version__}, {os.cpu_count()} CPUs; load average "
        f"{load_before[0]:.1f} before, {load_after[0]:.1f} after.")
    say()
    say(f"Wall-clock seconds, median (min–max) over {args.repeats} repeats, in turns; the one "
        f"process used {statistics.median(cpu):.2f} CPU seconds (median), "
        f"{statistics.median(cpu) / args.states * 1e6:.2f} µs per state.")
    say()
    say("| run | s | one process / this | target |")
    say("|---|---:|---:|---|")
    for way in ways:
        label = way if isinstance(way, str) else f"LocalCluster, {way} worker process" + \
            ("es" if way > 1 else "")
        ratio = one / statistics.median(times[way])
        target = (f"≥ 1.6: {'met' if ratio >= 1.6 else 'NOT met'}" if way == 2 else "")
        say(f"| {label} | {spread(times[way], '.2f')} | {ratio:.2f} | {target} |")
    say()
    worst = np.unravel_index(np.argmax(reference), reference.shape)
    say(f"Largest entry: |dtau_{worst[0] + 1}/dq_{worst[1] + 1}| = {reference.max():.1f} N m/rad; "
        f"column q_1 all zero: {not reference[:, 0].any()} (joint 1 turns about gravity).")
    if args.markdown:
        args.markdown.parent.mkdir(parents=True, exist_ok=True)
        args.markdown.write_text("\n".join(lines) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
