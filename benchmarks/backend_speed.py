"""Batch speed of the generated backends: NumPy, JAX (jit + vmap), PyTorch (CPU), dask.

Usage::

    python benchmarks/backend_speed.py [--states 10000] [--repeat 7] [--dask-states 200000]
                                       [--quick]

For the Panda arm (example-robot-data's ``panda.urdf`` with
``examples/scenes/panda_fingers_locked.yaml``: 7 joints), the NumPy, JAX and PyTorch modules
are generated into a temporary folder, then on the same random batch of ``--states`` states
(float64 everywhere):

* **numpy**: ``inverse_dynamics(q, qd, qdd)`` and ``mass_matrix(q)`` on the batch (the
  reference);
* **jax**: ``jax.jit(jax.vmap(f))`` on the same arrays as JAX arrays, compiled before timing
  (``lower(...).compile()``, its time reported apart) and run once more as warm-up;
  ``block_until_ready`` is inside the time; on the device JAX chooses. Once with jax.jit's
  defaults (the target) and once with ``compiler_options={"xla_disable_hlo_passes":
  "fusion"}`` (no target): XLA's CPU fusion copies the intermediates an output entry needs into
  every entry's loop, which for M costs more than fusing saves;
* **torch**: the functions on CPU tensors (no autograd recording), on one thread as NumPy's
  element-wise operations (the target), and on torch's default number of threads;
* **dask**: ``eomgen.analysis.batch.dask_map`` of the NumPy functions over ``--dask-states`` states in
  chunks of a quarter of them, made and kept on a ``distributed.LocalCluster`` of 2 worker
  processes with one thread each, against the plain NumPy batch on the same states in this
  process (throughput only; no target).

Each timing is repeated ``--repeat`` times; the table gives the median time per state and the
spread (min to max) and the ratio of medians to NumPy's, all measured in this run. Targets
(issue 12): jax <= 1 (no slower per state than NumPy), torch <= 2. Exit status 0 when both are
met, 2 otherwise. Every backend's result is checked against NumPy's (relative 1e-12) first.
"""

from __future__ import annotations

import argparse
import importlib
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

import eomgen  # noqa: E402
from eomgen.analysis.batch import dask_map  # noqa: E402
from eomgen.codegen.scene_generate import generate_scene  # noqa: E402
from eomgen.scene import load_scene  # noqa: E402

TARGETS = {"jax": 1.0, "torch": 2.0}
# (route, XLA compiler options, note): jax.jit's defaults (the target), and XLA's fusion pass
# turned off for this one function (each operation its own loop over the batch, as in NumPy)
JAX_ROUTES = (("jax jit+vmap", None, ""),
              ("(jax jit+vmap)", {"xla_disable_hlo_passes": "fusion"},
               "XLA fusion off (no target); "))


def panda_modules(outdir: Path):
    sys.path.insert(0, str(ROOT / "tests"))
    try:
        from support import erd_robots_dir
    finally:
        sys.path.pop(0)
    robots = erd_robots_dir()
    if robots is None:
        raise SystemExit("example-robot-data is not installed (pip install -e '.[bench]')")
    scene = load_scene(ROOT / "examples/scenes/panda_fingers_locked.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(robots / "panda_description/urdf/panda.urdf")
    generate_scene(model, scene, outdir, "numpy,jax,torch")
    sys.path.insert(0, str(outdir))
    return {kind: importlib.import_module(f"panda_{kind}") for kind in ("numpy", "jax", "torch")}


def timings(call, repeat: int) -> list[float]:
    call()  # warm-up (and compilation)
    out = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        out.append(time.perf_counter() - start)
    return out


def check(actual, expected, what: str) -> None:
    error = np.max(np.abs(np.asarray(actual) - expected)) / np.max(np.abs(expected))
    if not error <= 1e-12:
        raise SystemExit(f"{what} differs from NumPy by {error:.1e} (relative)")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10_000)
    parser.add_argument("--dask-states", type=int, default=200_000)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="1,000 states, 3 repeats")
    args = parser.parse_args(argv)
    if args.quick:
        args.states, args.dask_states, args.repeat = 1_000, 20_000, 3

    import jax
    jax.config.update("jax_enable_x64", True)
    import torch
    import dask.array as da
    from distributed import Client, LocalCluster

    with tempfile.TemporaryDirectory() as tmp:
        modules = panda_modules(Path(tmp))
        npm, jxm, thm = modules["numpy"], modules["jax"], modules["torch"]
        rng = np.random.default_rng(0)
        n = npm.NQ
        q, qd, qdd = (rng.uniform(-np.pi, np.pi, (args.states, n)),
                      rng.normal(size=(args.states, n)), rng.normal(size=(args.states, n)))
        jq, jqd, jqdd = (jax.device_put(a) for a in (q, qd, qdd))
        tq, tqd, tqdd = (torch.from_numpy(a) for a in (q, qd, qdd))
        rows = []
        for label, numpy_call, jax_function, jax_args, torch_call in (
                ("tau", lambda: npm.inverse_dynamics(q, qd, qdd), jxm.inverse_dynamics,
                 (jq, jqd, jqdd), lambda: thm.inverse_dynamics(tq, tqd, tqdd)),
                ("M", lambda: npm.mass_matrix(q), jxm.mass_matrix, (jq,),
                 lambda: thm.mass_matrix(tq))):
            expected = numpy_call()
            compiled = []
            for route, options, note in JAX_ROUTES:
                start = time.perf_counter()  # compile time apart from the timings
                jax_f = jax.jit(jax.vmap(jax_function), compiler_options=options).lower(
                    *jax_args).compile()
                compiled.append((route, jax_f, time.perf_counter() - start, note))
                check(jax_f(*jax_args), expected, f"{route} {label}")
            with torch.no_grad():
                check(torch_call(), expected, f"torch {label}")
            base = timings(numpy_call, args.repeat)
            rows.append((label, "numpy", base, base, ""))
            for route, jax_f, compile_s, note in compiled:
                jax_t = timings(lambda: jax_f(*jax_args).block_until_ready(), args.repeat)
                rows.append((label, route, jax_t, base,
                             f"{note}compiled in {compile_s:.1f} s on {jax.devices()[0]}"))
            threads = torch.get_num_threads()
            with torch.no_grad():
                torch.set_num_threads(1)  # as NumPy's element-wise operations
                torch_t = timings(torch_call, args.repeat)
                rows.append((label, "torch cpu", torch_t, base, "1 thread"))
                torch.set_num_threads(threads)
                torch_t = timings(torch_call, args.repeat)
                rows.append((label, "(torch cpu)", torch_t, base,
                             f"{threads} threads (torch's default; no target)"))

        # dask on a 2-worker LocalCluster against the plain NumPy batch on the same states
        # (the states are made on the workers and kept there: the time is the evaluation's)
        chunk = -(-args.dask_states // 4)
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            client.upload_file(str(Path(tmp) / "panda_numpy.py"))
            generator = da.random.default_rng(1)
            lazy_states = client.persist([
                generator.uniform(-np.pi, np.pi, (args.dask_states, n), chunks=(chunk, n))
                for _ in range(3)])
            big = [x.compute() for x in lazy_states]
            for label, f, k in (("tau", npm.inverse_dynamics, 3), ("M", npm.mass_matrix, 1)):
                lazy = dask_map(f, *lazy_states[:k])
                base = timings(lambda: f(*big[:k]), args.repeat)
                check(lazy.compute(), f(*big[:k]), f"dask {label}")
                dask_t = timings(lambda: lazy.compute(), args.repeat)
                rows.append((f"{label} ({args.dask_states} states)", "numpy", base, base, ""))
                rows.append((f"{label} ({args.dask_states} states)", "dask 2 workers", dask_t,
                             base, f"4 chunks of {chunk}"))

    print(f"Panda ({n} joints), {args.states} states, {args.repeat} repeats; time per state "
          "(median, min-max), ratio of medians to NumPy's in this run\n")
    print("| output | route | per state | spread | / numpy | note |")
    print("| --- | --- | ---: | ---: | ---: | --- |")
    ok = True
    for label, route, t, base, note in rows:
        states = args.dask_states if "states)" in label else args.states
        median = statistics.median(t) / states
        ratio = statistics.median(t) / statistics.median(base)
        spread = f"{min(t) / states * 1e6:.3f}-{max(t) / states * 1e6:.3f} µs"
        print(f"| {label} | {route} | {median * 1e6:.3f} µs | {spread} | {ratio:.2f} | {note} |")
        kind = route.split()[0]
        if kind in TARGETS and ratio > TARGETS[kind]:
            ok = False
            print(f"  target missed: {route} / numpy = {ratio:.2f} > {TARGETS[kind]}")
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
