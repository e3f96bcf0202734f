"""Readable symbolic results in bounded time (issue #14): derive → LaTeX for the teaching arms,
display of any robot, ``dyn.lambdify()``, and ``eomgen notebook`` end to end.

Usage::

    python benchmarks/readable_speed.py [--quick] [--repeat 3] [--no-notebooks]

Every measurement runs in a fresh Python process (so SymPy's caches start empty, as for a
user) and times only the step named, not the interpreter start-up or the imports:

* **derive → LaTeX** (teaching arms: elbow, SCARA, Stanford-type, cylindrical, PUMA 560 first
  three joints): ``eomgen.derive(model)`` then ``dyn._repr_latex_()`` (the Jupyter display),
  and separately the LaTeX document (``render_document``). Targets: ≤ 5 s (PUMA: ≤ 10 s).
* **display**: ``derive`` + ``_repr_latex_()`` for a random 3-joint arm with general axes
  (the robot of the issue whose display did not finish in 20 minutes) and random 5- and
  7-joint arms. Target: ≤ 10 s for the display.
* **symbolic access**: first access of ``dyn.M``, ``.C``, ``.g``, ``.tau`` of larger models
  (PUMA 560, random 5- and 7-joint arms, Panda): an ordinary matrix when written out within
  the work bound, else the named form (``ProgramMatrix``). Target: ≤ 2 s each.
* **lambdify**: ``dyn.lambdify()`` for the Panda (7 joints, fingers locked; needs
  example-robot-data), against ``sympy.lambdify(M, cse=True)`` of the substituted program tree for
  a 3-joint arm as a reference of the old route; its M, C, g are checked against the generated
  NumPy module's at random states. Target: ≤ 2 s.
* **notebook**: ``eomgen notebook`` and its execution with nbclient (elbow, random 3-joint
  arm, Panda). Target: ≤ 60 s.

Reported: median and spread (min-max) over ``--repeat`` runs (``--quick``: 1 run, fewer robots).
The machine's load shows in the spread; compare the targets with the medians.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import textwrap
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

PRELUDE = f"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
sys.path.insert(0, {str(ROOT)!r})
sys.path.insert(0, {str(ROOT / "tests")!r})
import numpy as np
import eomgen
from dataclasses import replace


def random_arm(n, seed=0):
    from support.reference import random_robot
    return replace(random_robot(np.random.default_rng(seed), n), name=f"random_{{n}}dof")


def panda():
    from support import erd_robots_dir
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene
    robots = erd_robots_dir()
    if robots is None:
        return None
    model = eomgen.load(robots / "panda_description" / "urdf" / "panda.urdf")
    return apply_scene(model, load_scene({str(ROOT / "examples/scenes/panda_fingers_locked.yaml")!r})).model


def model_named(name):
    if name.startswith("random"):
        return random_arm(int(name[len("random"):]))
    if name == "panda":
        return panda()
    return eomgen.load(eomgen.example_path(name))
"""


def run(code: str) -> dict:
    """Run ``code`` (after PRELUDE) in a fresh interpreter; it prints one JSON object."""
    # this checkout first on the path, for the notebooks' kernels too (not an installed eomgen)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])}
    done = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(code)],
                          capture_output=True, text=True, cwd=ROOT, env=env)
    if done.returncode != 0:
        raise SystemExit(f"benchmark step failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def derive_to_latex(name: str) -> dict:
    return run(f"""
    from eomgen.codegen import make_job
    from eomgen.codegen.backends.latex_backend import render_document
    model = model_named({name!r})
    start = time.perf_counter()
    dyn = eomgen.derive(model)
    tex = dyn._repr_latex_()
    display = time.perf_counter() - start
    start = time.perf_counter()
    dyn = eomgen.derive(model, outputs=("M", "C", "g", "tau"))
    document = render_document(make_job(dyn))
    print(json.dumps({{"display": display, "document": time.perf_counter() - start,
                      "textbook": "pmatrix" in tex, "floats": "." in tex.split("joints")[-1]}}))
    """)


def lambdify_panda() -> dict:
    return run("""
    import importlib.util, tempfile, pathlib
    from eomgen.codegen import make_job
    from eomgen.codegen.backends.numpy_backend import generate_numpy
    model = panda()
    if model is None:
        print(json.dumps({"skipped": "example-robot-data is not installed"}))
        raise SystemExit(0)
    dyn = eomgen.derive(model)
    start = time.perf_counter()
    f = dyn.lambdify()
    seconds = time.perf_counter() - start
    [file] = generate_numpy(make_job(dyn, ["mass_matrix", "coriolis_matrix", "gravity_vector"]))
    path = pathlib.Path(tempfile.mkdtemp()) / file.name
    path.write_text(file.content)
    spec = importlib.util.spec_from_file_location("panda_numpy", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rng = np.random.default_rng(0)
    q, qd = rng.uniform(-2, 2, (2, 100, model.dof))
    error = max(
        float(np.max(np.abs(f.M(q) - module.mass_matrix(q)))),
        float(np.max(np.abs(f.C(q, qd) - module.coriolis_matrix(q, qd)))),
        float(np.max(np.abs(f.g(q) - module.gravity_vector(q)))))
    print(json.dumps({"lambdify": seconds, "max_abs_difference": error, "dof": model.dof}))
    """)


def sympy_lambdify_reference(n: int) -> dict:
    return run(f"""
    import sympy as sp
    dyn = eomgen.derive(random_arm({n}), simplify=False)
    tree = dyn.program.expand(dyn.program.output("M"))  # what dyn.M was before the named form
    start = time.perf_counter()
    f = sp.lambdify(list(dyn.q), tree, cse=True)
    sympy_seconds = time.perf_counter() - start
    start = time.perf_counter()
    dyn.lambdify()
    print(json.dumps({{"sympy": sympy_seconds, "eomgen": time.perf_counter() - start}}))
    """)


def symbolic_access(name: str) -> dict:
    return run(f"""
    from eomgen.symbolic.named import ProgramMatrix
    model = model_named({name!r})
    if model is None:
        print(json.dumps({{"skipped": "example-robot-data is not installed"}}))
        raise SystemExit(0)
    dyn = eomgen.derive(model, outputs=("M", "C", "g", "tau"))
    out = {{"dof": model.dof}}
    for key in ("M", "C", "g", "tau"):
        start = time.perf_counter()
        value = getattr(dyn, key)
        out[key] = [time.perf_counter() - start,
                    "named" if isinstance(value, ProgramMatrix) else "Matrix"]
    print(json.dumps(out))
    """)


def notebook(name: str) -> dict:
    return run(f"""
    import nbclient, tempfile
    from eomgen.teach.notebook import build_notebook
    model = model_named({name!r})
    if model is None:
        print(json.dumps({{"skipped": "example-robot-data is not installed"}}))
        raise SystemExit(0)
    bundled = not {name!r}.startswith(("random", "panda"))
    folder = tempfile.mkdtemp()
    start = time.perf_counter()
    nb = build_notebook(model, eomgen.example_path({name!r}) if bundled else None)
    build = time.perf_counter() - start
    if not bundled:  # no description file: the first code cell builds the model as here
        setup = nb.cells[2]
        setup.source = setup.source.replace(
            'model = eomgen.load(eomgen.example_path("planar_2link"))',
            {PRELUDE!r} + "\\nmodel = model_named(" + repr({name!r}) + ")")
    start = time.perf_counter()
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={{"metadata": {{"path": folder}}}}).execute()
    print(json.dumps({{"build": build, "execute": time.perf_counter() - start,
                      "textbook": any("textbook_derivation" in c.source for c in nb.cells)}}))
    """)


def summary(values: list[float]) -> str:
    if len(values) == 1:
        return f"{values[0]:7.2f} s"
    return f"{statistics.median(values):7.2f} s ({min(values):.2f}-{max(values):.2f})"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one run, fewer robots")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-notebooks", action="store_true")
    args = parser.parse_args()
    repeat = 1 if args.quick else args.repeat
    failed = []

    print("derive -> LaTeX (display; document), target <= 5 s (PUMA 3 joints: <= 10 s)")
    arms = ["elbow_rrr", "scara_rrp", "stanford_rrp", "cylindrical_rpp", "puma560_arm3"]
    for name in arms:
        runs = [derive_to_latex(name) for _ in range(repeat)]
        display = [r["display"] for r in runs]
        document = [r["document"] for r in runs]
        target = 10.0 if name.startswith("puma") else 5.0
        ok = statistics.median(display) <= target and statistics.median(document) <= target
        failed += [] if ok and runs[0]["textbook"] else [name]
        print(f"  {name:16s} display {summary(display)}  document {summary(document)}  "
              f"textbook form: {runs[0]['textbook']}  {'ok' if ok else 'MISSED'}")

    print("display of any robot (derive + _repr_latex_), target <= 10 s")
    for name in (["random3"] if args.quick else ["random3", "random5", "random7"]):
        runs = [derive_to_latex(name) for _ in range(repeat)]
        display = [r["display"] for r in runs]
        ok = statistics.median(display) <= 10.0
        failed += [] if ok else [name]
        print(f"  {name:16s} display {summary(display)}  "
              f"({'textbook form' if runs[0]['textbook'] else 'summary'})  "
              f"{'ok' if ok else 'MISSED'}")

    print("dyn.M, C, g, tau of larger models (first access: written out or named), target "
          "<= 2 s each")
    for name in (["random5"] if args.quick else ["puma560_dh", "random5", "random7", "panda"]):
        runs = [symbolic_access(name) for _ in range(repeat)]
        if "skipped" in runs[0]:
            print(f"  {name}: skipped ({runs[0]['skipped']})")
            continue
        parts = []
        for key in ("M", "C", "g", "tau"):
            seconds = [r[key][0] for r in runs]
            ok = statistics.median(seconds) <= 2.0
            failed += [] if ok else [f"{name} dyn.{key}"]
            parts.append(f"{key} {summary(seconds).strip()} {runs[0][key][1]}")
        print(f"  {name:16s} ({runs[0]['dof']} joints) " + ";  ".join(parts))

    print("dyn.lambdify(), target <= 2 s for the Panda")
    runs = [lambdify_panda() for _ in range(repeat)]
    if "skipped" in runs[0]:
        print(f"  panda: skipped ({runs[0]['skipped']})")
    else:
        seconds = [r["lambdify"] for r in runs]
        ok = statistics.median(seconds) <= 2.0 and runs[0]["max_abs_difference"] < 1e-9
        failed += [] if ok else ["panda lambdify"]
        print(f"  panda ({runs[0]['dof']} joints) {summary(seconds)}; largest |difference| to "
              f"the generated NumPy module over 100 states: {runs[0]['max_abs_difference']:.1e}"
              f"  {'ok' if ok else 'MISSED'}")
    reference = sympy_lambdify_reference(3)
    print(f"  reference, random 3-joint arm: sympy.lambdify(dyn.M, cse=True) "
          f"{reference['sympy']:.2f} s, dyn.lambdify() {reference['eomgen']:.2f} s "
          f"(ratio {reference['sympy'] / reference['eomgen']:.1f})")

    if not args.no_notebooks:
        print("eomgen notebook end to end (build + execute), target <= 60 s")
        for name in (["elbow_rrr"] if args.quick else ["elbow_rrr", "random3", "panda"]):
            r = notebook(name)
            if "skipped" in r:
                print(f"  {name}: skipped ({r['skipped']})")
                continue
            total = r["build"] + r["execute"]
            ok = total <= 60.0
            failed += [] if ok else [f"{name} notebook"]
            print(f"  {name:16s} build {r['build']:.2f} s, execute {r['execute']:.2f} s "
                  f"({'textbook cells' if r['textbook'] else 'large-model cells'})  "
                  f"{'ok' if ok else 'MISSED'}")
    print("all targets met" if not failed else f"missed: {', '.join(failed)}")
    return 0 if not failed else 2


if __name__ == "__main__":
    sys.exit(main())
