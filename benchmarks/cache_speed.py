"""Derivation cache speed: ``eomgen generate`` the first time and again, unchanged.

Usage::

    python benchmarks/cache_speed.py [--repeat 5] [--backend all] [--csv] [--quick]

``--quick``: the NumPy backend only and 2 cached runs (seconds instead of a minute).

For the PUMA 560 (``eomgen/robots/puma560_dh.yaml``) and the UR5 (example-robot-data's
``ur5_robot.urdf``), with a fresh cache folder each:

* **first**: ``python -m eomgen.cli generate FILE -o OUT --cache-dir CACHE``, a cache miss: load,
  derive, run every backend (the C backend compiles a shared library), write, store the entry.
* **cached**: the same command again, ``--repeat`` times (best kept, as timeit does): the entry
  is read, checked (HMAC, hash, key, version) and its files written.
* **ratio** = first / cached. Target (issue #6): at least 20.

Times are wall-clock seconds of the whole process (interpreter start-up included) and, beside
them, its CPU seconds with its children's (the C compiler). The cached run's files must be
byte-identical to the first run's; the script stops otherwise. Exit status 0 when both robots
reach the target, 2 when one does not.
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TARGET = 20.0


def ur5_path() -> Path | None:
    sys.path.insert(0, str(ROOT / "tests"))
    try:
        from support import erd_robots_dir
    finally:
        sys.path.pop(0)
    robots = erd_robots_dir()
    return robots / "ur_description" / "urdf" / "ur5_robot.urdf" if robots else None


def run(description: Path, outdir: Path, cache: Path, backend: str) -> tuple[float, float, str]:
    """(wall s, CPU s of the process and its children, stderr) of one ``eomgen generate``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "eomgen.cli", "generate", str(description),
                           "-o", str(outdir), "--cache-dir", str(cache), "--backend", backend],
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"eomgen generate {description} failed:\n{done.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, done.stderr


def files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def measure(label: str, description: Path, repeat: int, backend: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        cache = tmp / "cache"
        first_wall, first_cpu, stderr = run(description, tmp / "first", cache, backend)
        if "using cached result" in stderr:
            raise SystemExit("the first run was answered from the cache")
        cached = []
        for k in range(repeat):
            wall, cpu, stderr = run(description, tmp / f"cached{k}", cache, backend)
            if "using cached result" not in stderr:
                raise SystemExit(f"run {k + 2} was not answered from the cache:\n{stderr}")
            if files(tmp / f"cached{k}") != files(tmp / "first"):
                raise SystemExit(f"{label}: the cached files differ from the first run's")
            cached.append((wall, cpu))
        entry_bytes = sum(p.stat().st_size for p in (cache / "entries").glob("*.entry"))
    best_wall = min(w for w, _ in cached)
    best_cpu = min(c for _, c in cached)
    return {"robot": label, "file": description.name, "backend": backend,
            "first_wall_s": round(first_wall, 3), "first_cpu_s": round(first_cpu, 3),
            "cached_wall_s": round(best_wall, 3), "cached_cpu_s": round(best_cpu, 3),
            "ratio_wall": round(first_wall / best_wall, 1),
            "ratio_cpu": round(first_cpu / best_cpu, 1),
            "entry_kB": round(entry_bytes / 1024), "repeat": repeat}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=None,
                        help="cached runs (best kept; default 5, 2 with --quick)")
    parser.add_argument("--backend", default=None,
                        help="backends, as eomgen generate takes (default all; numpy with "
                             "--quick)")
    parser.add_argument("--quick", action="store_true",
                        help="the NumPy backend only, 2 cached runs")
    parser.add_argument("--csv", action="store_true",
                        help="also write benchmarks/results/cache_speed.csv")
    args = parser.parse_args()
    if args.repeat is None:
        args.repeat = 2 if args.quick else 5
    if args.backend is None:
        args.backend = "numpy" if args.quick else "all"
    robots = [("PUMA 560", ROOT / "eomgen" / "robots" / "puma560_dh.yaml")]
    ur5 = ur5_path()
    if ur5 is None:
        print("example-robot-data not installed: UR5 skipped", file=sys.stderr)
    else:
        robots.append(("UR5", ur5))
    if os.getloadavg()[0] > 0.5:
        print(f"note: load average {os.getloadavg()[0]:.2f}; wall-clock times include other "
              "work, CPU times do not", file=sys.stderr)
    rows = [measure(label, path, args.repeat, args.backend) for label, path in robots]
    print(f"eomgen generate --backend {args.backend}: first run (cache miss) and best of "
          f"{args.repeat} cached runs; wall-clock s (CPU s with children)")
    print(f"{'robot':10} {'first':>16} {'cached':>16} {'ratio':>14} {'entry':>8}")
    for r in rows:
        print(f"{r['robot']:10} {r['first_wall_s']:7.2f} ({r['first_cpu_s']:5.2f})"
              f" {r['cached_wall_s']:7.3f} ({r['cached_cpu_s']:5.3f})"
              f" {r['ratio_wall']:6.1f}× ({r['ratio_cpu']:4.1f}×) {r['entry_kB']:5d} kB")
    ok = all(r["ratio_wall"] >= TARGET for r in rows)
    print(f"target: cached ≥ {TARGET:g}× faster than the first run: "
          + ("met" if ok else "NOT met"))
    if args.csv:
        out = HERE / "results" / "cache_speed.csv"
        out.parent.mkdir(exist_ok=True)
        with out.open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        print(f"wrote {out.relative_to(ROOT)}")
    return 0 if ok else 2


if __name__ == "__main__":
    sys.exit(main())
