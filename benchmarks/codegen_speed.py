"""Code generation benchmark: size, generation time and run time of the generated code.

Measures in one run, side by side, the targets of the issue "Code generation" on the Franka
Panda (example-robot-data ``panda.urdf``, fingers locked at 0), with the UR5 and the PUMA 560
(no Pinocchio reference: it has no URDF) for context:

1. size: arithmetic operations (SymPy ``count_ops`` after elimination) of M, C and g as one
   shared program, of each generated function and of ``inverse_dynamics``; SX instruction
   counts of the generated CasADi functions; beside them, numbers of other tools *quoted* from
   the issue (labelled "quoted, not measured here");
2. generation time of ``--backend numpy,casadi`` in a fresh process, so that import time counts:
   the library call (``lock_joints`` + ``generate``) and the CLI ``eomgen generate`` (on a copy
   of panda.urdf with the fingers declared fixed, since the CLI cannot lock joints);
3. the compiled C functions (CasADi's code generator; the ``.so`` loaded with
   ``casadi.external`` and called through ``Function.buffer()`` on preallocated NumPy arrays)
   against ``pinocchio.crba``, ``rnea`` and crba + ``computeCoriolisMatrix`` +
   ``computeGeneralizedGravity``, all called in a Python loop on the same state;
4. the generated NumPy ``inverse_dynamics`` and ``mass_matrix`` on a batch of random states
   against ``pinocchio.rnea`` / ``crba`` in a Python loop over the same states, and the NumPy
   function on one state.

Every run-time comparison also checks that both sides agree (max abs difference, and relative
to the largest value).

Usage::

    python benchmarks/codegen_speed.py            # about 3 minutes on a shared 2-core machine
    python benchmarks/codegen_speed.py --quick    # about a minute: fewer calls, one generation
    python benchmarks/codegen_speed.py --csv      # also write benchmarks/results/codegen_speed.csv

Times are medians with the spread (min–max) of the repeats; the two sides of a comparison are
timed in turns (ours, reference, ours, …) with ``timeit`` (garbage collection off) after a
warm-up, on the wall clock (``time.perf_counter``). The NumPy batch is also timed in CPU time
(``time.process_time``), which waiting for a CPU on a busy machine does not inflate. Nothing
here asserts on a time: the table says which targets this run met. Generation writes into a
temporary folder. Needs the ``bench`` extra (Pinocchio, example-robot-data) and a C compiler.
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import os
import platform
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import time
import timeit
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # measure this checkout, not some installed copy

import casadi as ca  # noqa: E402

import eomgen  # noqa: E402
from eomgen.codegen import Job, available_backends, make_job  # noqa: E402
from eomgen.codegen.backends.casadi_backend import library_name  # noqa: E402
from eomgen.codegen.generate import write_atomically  # noqa: E402
from eomgen.dynamics import ALL_OUTPUTS  # noqa: E402
from eomgen.model import lock_joints  # noqa: E402

RESULTS_CSV = ROOT / "benchmarks" / "results" / "codegen_speed.csv"
PANDA_URDF = Path("panda_description", "urdf", "panda.urdf")
UR5_URDF = Path("ur_description", "urdf", "ur5_robot.urdf")
PANDA_FINGERS = {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}
FUNCTIONS = ("mass_matrix", "coriolis_matrix", "gravity_vector", "inverse_dynamics")
QUOTED = "quoted, not measured here"

# Reference numbers quoted from the issue "Code generation" (not measured by this script).
QUOTED_NAIVE_LAGRANGIAN_MCG_OPS = 31_000  # naive Lagrangian + one CSE pass, Panda M, C, g
QUOTED_ADAM_MASS_MATRIX_SX = 2_649        # ADAM's CasADi mass matrix, SX instructions
QUOTED_URDF2CASADI_RNEA_SX = 1_408        # urdf2casadi's RNEA, SX instructions
QUOTED_RNEA_6DOF_OPS = 850 + 740          # general RNEA, 6 joints: ~850 mul + 740 add
                                          # (Corke; Hollerbach)

# Targets of the issue (for the Panda).
TARGET_MCG_OPS = 6_000
TARGET_TAU_OPS = 1_400
TARGET_GENERATION_S = 20.0
TARGET_CRBA_RATIO = 1.5
TARGET_BATCH_SPEEDUP = 3.0
AGREEMENT = 1e-9                      # max abs difference / max |value| of the reference


@dataclass(frozen=True)
class Settings:
    calls: int             # calls per timing repeat of a single-state function
    numpy_calls: int       # calls per repeat of the (slow) single-state NumPy function
    repeats: int           # timing repeats (median and spread over these)
    batch: int             # states in the NumPy batch
    generation_runs: int   # fresh-process generation runs of each kind
    cli_run: bool          # also time the CLI (beside the library call)

    @classmethod
    def choose(cls, quick: bool) -> "Settings":
        if quick:
            return cls(calls=2_000, numpy_calls=20, repeats=5, batch=10_000, generation_runs=1,
                       cli_run=False)
        return cls(calls=20_000, numpy_calls=200, repeats=7, batch=10_000, generation_runs=5,
                   cli_run=True)


# --------------------------------------------------------------------------------------------
# Results


@dataclass(frozen=True)
class Value:
    """A measurement: the median of ``samples`` (or one exact number) with its spread."""

    samples: tuple[float, ...]

    @classmethod
    def exact(cls, x: float) -> "Value":
        return cls((float(x),))

    @property
    def median(self) -> float:
        return statistics.median(self.samples)

    def format(self, spec: str) -> str:
        """The median in format ``spec``, followed by (min–max) when the samples differ."""
        text = format(self.median, spec)
        if len(set(self.samples)) > 1:
            text += f" ({min(self.samples):{spec}}–{max(self.samples):{spec}})"
        return text


@dataclass(frozen=True)
class Row:
    robot: str
    section: str
    quantity: str
    unit: str
    ours: Value
    reference: Value | None = None
    reference_source: str = ""
    target: str = ""
    met: bool | None = None      # None: no target for this row
    spec: str = ",.0f"           # number format of ours and reference

    @property
    def ratio(self) -> float | None:
        """ours / reference (below 1: ours smaller or faster)."""
        if self.reference is None or self.reference.median == 0:
            return None
        return self.ours.median / self.reference.median

    def cells(self) -> list[str]:
        unit = f" {self.unit}" if self.unit else ""
        reference = ""
        if self.reference is not None:
            reference = self.reference.format(self.spec) + unit
            if self.reference_source:
                reference += f" [{self.reference_source}]"
        ratio = "" if self.ratio is None else format(
            self.ratio, ".1e" if self.spec.endswith("e") else ".2f")
        met = {None: "", True: "yes", False: "NO"}[self.met]
        return [self.robot, self.quantity, self.ours.format(self.spec) + unit, reference, ratio,
                self.target, met]


@dataclass
class Report:
    rows: list[Row] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, *args, **kwargs) -> None:
        self.rows.append(Row(*args, **kwargs))

    def print_table(self) -> None:
        header = ["robot", "quantity", "ours", "reference", "ours/ref", "target", "met?"]
        widths = [max(len(header[i]), *(len(r.cells()[i]) for r in self.rows))
                  for i in range(len(header))]

        def line(cells):
            return "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()

        section = None
        print(line(header))
        print("  ".join("-" * w for w in widths))
        for row in self.rows:
            if row.section != section:
                section = row.section
                print(f"[{section}]")
            print(line(row.cells()))

    def write_csv(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(["robot", "section", "quantity", "unit", "ours", "ours_min",
                             "ours_max", "reference", "reference_min", "reference_max",
                             "reference_source", "ratio_ours_over_reference", "target", "met"])
            for r in self.rows:
                ref = r.reference
                writer.writerow([
                    r.robot, r.section, r.quantity, r.unit, r.ours.median, min(r.ours.samples),
                    max(r.ours.samples), "" if ref is None else ref.median,
                    "" if ref is None else min(ref.samples),
                    "" if ref is None else max(ref.samples),
                    r.reference_source, "" if r.ratio is None else r.ratio, r.target,
                    "" if r.met is None else r.met])


# --------------------------------------------------------------------------------------------
# Robots


def erd_robots_dir() -> Path:
    """example-robot-data's ``robots/`` folder ($EXAMPLE_ROBOT_DATA_ROBOTS, else site-packages).

    A short version of ``tests/support/__init__.py``'s lookup (that module needs pytest, which the
    ``bench`` extra does not install).
    """
    suffix = Path("cmeel.prefix", "share", "example-robot-data", "robots")
    override = os.environ.get("EXAMPLE_ROBOT_DATA_ROBOTS")
    candidates = [Path(override)] if override else []
    candidates += [Path(sysconfig.get_paths()[key]) / suffix for key in ("purelib", "platlib")]
    for candidate in candidates:
        if candidate.is_dir():
            return candidate
    sys.exit("codegen_speed: example-robot-data not found; pip install -e .[bench] "
             "or set EXAMPLE_ROBOT_DATA_ROBOTS")


@dataclass(frozen=True)
class Robot:
    label: str
    path: Path
    locked: dict[str, float]
    has_pinocchio: bool
    targets: bool            # the targets apply to this robot

    def load(self) -> eomgen.RobotModel:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # Panda's <mimic>, PUMA 560's published inertias
            model = eomgen.load(self.path)
        return lock_joints(model, self.locked) if self.locked else model


def robots() -> list[Robot]:
    erd = erd_robots_dir()
    return [
        Robot("panda", erd / PANDA_URDF, PANDA_FINGERS, True, True),
        Robot("ur5", erd / UR5_URDF, {}, True, False),
        Robot("puma560", eomgen.example_path("puma560_dh"), {}, False, False),
    ]


def pinocchio_model(robot: Robot, joint_names: tuple[str, ...]):
    """Pinocchio's model of ``robot`` (the same joints locked at the same positions)."""
    import pinocchio as pin

    full = pin.buildModelFromUrdf(str(robot.path))
    if robot.locked:
        q_lock = pin.neutral(full)
        for name, value in robot.locked.items():
            q_lock[full.idx_qs[full.getJointId(name)]] = value
        model = pin.buildReducedModel(full, [full.getJointId(n) for n in robot.locked], q_lock)
    else:
        model = full
    names = tuple(model.names[1:])
    if names != joint_names or model.nq != model.nv or model.nq != len(joint_names):
        raise RuntimeError(f"{robot.label}: Pinocchio's joints {names} (nq {model.nq}, nv "
                           f"{model.nv}) do not match eomgen's {joint_names}")
    return model


def load_module(path: Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# --------------------------------------------------------------------------------------------
# Timing


@dataclass(frozen=True)
class Loop:
    """``stmt`` run ``number`` times per timing; each run processes ``units`` calls or states."""

    stmt: str
    namespace: dict
    number: int = 1
    units: int = 1


def time_us(loops: list[Loop | None], repeats: int, clock=time.perf_counter
            ) -> list[Value | None]:
    """µs per unit of each loop: ``repeats`` timings each, after a warm-up.

    The loops take turns (ours, reference, ours, …) so that a change in the machine's load
    affects both sides of a comparison alike. ``None`` entries give ``None``.
    """
    timers = [None if loop is None else timeit.Timer(loop.stmt, globals=loop.namespace, timer=clock)
              for loop in loops]
    for timer, loop in zip(timers, loops):
        if timer is not None:
            timer.timeit(max(1, loop.number // 10))
    samples: list[list[float]] = [[] for _ in loops]
    for _ in range(repeats):
        for timer, loop, out in zip(timers, loops, samples):
            if timer is not None:
                out.append(timer.timeit(loop.number) / (loop.number * loop.units) * 1e6)
    return [Value(tuple(out)) if out else None for out in samples]


def compiled_function(library: Path, name: str, inputs: list[np.ndarray]):
    """``name`` from ``library`` through CasADi's buffer interface: (evaluate, output array).

    The output array is dense (column-major, matching CasADi's nonzero order) and is refilled
    by each ``evaluate()``; ``inputs`` are read at each call.
    """
    f = ca.external(name, str(library))
    sparsity = f.sparsity_out(0)
    if sparsity.nnz() != sparsity.numel():
        raise RuntimeError(f"{name}: sparse output; this benchmark expects a dense one")
    flat = np.zeros(sparsity.numel())
    buffer, evaluate = f.buffer()
    for i, x in enumerate(inputs):
        buffer.set_arg(i, memoryview(x))
    buffer.set_res(0, memoryview(flat))
    evaluate()
    if buffer.ret() != 0:
        raise RuntimeError(f"{name}: evaluation returned {buffer.ret()}")
    out = flat.reshape(f.size_out(0), order="F") if f.size2_out(0) > 1 else flat
    return evaluate, out, buffer  # the buffer object must outlive evaluate


def time_generation_subprocess(command: list[str], runs: int) -> Value:
    """Wall-clock seconds of ``command`` in a fresh process (interpreter start and imports)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        result = subprocess.run(command, cwd=ROOT, env=env, capture_output=True, text=True)
        times.append(time.perf_counter() - start)
        if result.returncode != 0:
            raise RuntimeError(f"{' '.join(command)} failed:\n{result.stderr[-2000:]}")
    return Value(tuple(times))


_LIBRARY_SCRIPT = """\
import sys, warnings
warnings.simplefilter("ignore")
import eomgen
from eomgen.codegen.generate import generate
from eomgen.model import lock_joints
model = lock_joints(eomgen.load(sys.argv[1]), {locked!r})
generate(model, sys.argv[2], "numpy,casadi", cache=False)
"""


# --------------------------------------------------------------------------------------------
# The benchmark


def urdf_with_fixed_joints(path: Path, names: dict[str, float], out: Path) -> Path:
    """A copy of the URDF ``path`` with the joints ``names`` (all locked at 0) made fixed.

    The CLI cannot lock joints; a joint locked at 0 is the same joint declared fixed.
    """
    if any(value != 0 for value in names.values()):
        raise ValueError("only joints locked at 0 can be declared fixed in a URDF copy")
    tree = ElementTree.parse(path)
    joints = {j.get("name"): j for j in tree.getroot().iter("joint")}
    for name in names:
        joints[name].set("type", "fixed")
    tree.write(out)
    return out


def benchmark_generation(robot: Robot, settings: Settings, report: Report, tmp: Path) -> None:
    """Target 2: generation time of numpy,casadi for the Panda in a fresh process."""
    print(f"  {robot.label}: fresh-process generation ({settings.generation_runs} run(s) "
          "each) …", flush=True)
    library = time_generation_subprocess(
        [sys.executable, "-c", _LIBRARY_SCRIPT.format(locked=robot.locked), str(robot.path),
         str(tmp / "library")], settings.generation_runs)
    report.add(robot.label, "2 generation time", "generate() numpy,casadi, fresh process",
               "s", library, target=f"≤ {TARGET_GENERATION_S:g} s",
               met=library.median <= TARGET_GENERATION_S, spec=".1f")
    if settings.cli_run:
        fixed = urdf_with_fixed_joints(robot.path, robot.locked, tmp / robot.path.name)
        cli = time_generation_subprocess(
            [sys.executable, "-m", "eomgen.cli", "generate", str(fixed), "--backend",
             "numpy,casadi", "-o", str(tmp / "cli"), "--quiet", "--no-cache"],
            settings.generation_runs)
        report.add(robot.label, "2 generation time", "CLI eomgen generate --backend "
                   "numpy,casadi", "s", cli, target=f"≤ {TARGET_GENERATION_S:g} s",
                   met=cli.median <= TARGET_GENERATION_S, spec=".1f")


@dataclass(frozen=True)
class Generated:
    """One robot's derived dynamics and generated, loaded code."""

    dyn: eomgen.Dynamics
    job: Job
    numpy_module: object         # the loaded <robot>_numpy.py
    casadi_module: object        # the loaded <robot>_casadi.py
    library: Path                # the compiled lib<robot>_casadi.so


def generate_code(robot: Robot, model: eomgen.RobotModel, tmp: Path, report: Report) -> Generated:
    """Derive once and run the numpy, casadi and c backends on that job (as render_files does),
    into ``tmp``; note each stage's time."""
    start = time.perf_counter()
    dyn = eomgen.derive(model, outputs=ALL_OUTPUTS, simplify=False)
    stages = {"derive": time.perf_counter() - start}
    job = make_job(dyn)
    registry = available_backends()
    files = []
    for name in ("numpy", "casadi", "c"):
        start = time.perf_counter()
        files += registry[name].generate(job)
        stages[name] = time.perf_counter() - start
    outdir = tmp / robot.label
    write_atomically(files, outdir)
    report.notes.append(f"{robot.label}: in-process generation stages (one run): " + ", ".join(
        f"{k} {v:.2f} s" for k, v in stages.items()) + f"; total {sum(stages.values()):.2f} s")
    return Generated(dyn, job, load_module(outdir / f"{job.stem}_numpy.py"),
                     load_module(outdir / f"{job.stem}_casadi.py"),
                     outdir / library_name(job.stem))


def measure_size(robot: Robot, code: Generated, report: Report) -> None:
    """Target 1: operation counts and CasADi SX instruction counts."""
    label, section, targeted = robot.label, "1 size", robot.targets
    mcg = code.dyn.operation_count(["M", "C", "g"])
    report.add(label, section, "ops M, C, g (shared program)", "", Value.exact(mcg),
               Value.exact(QUOTED_NAIVE_LAGRANGIAN_MCG_OPS) if targeted else None,
               f"naive Lagrangian + CSE, {QUOTED}" if targeted else "",
               f"≤ {TARGET_MCG_OPS:,}" if targeted else "",
               (mcg <= TARGET_MCG_OPS) if targeted else None)
    counts = {s.name: s.operation_count for s in code.job.specs}
    for name in FUNCTIONS[:3]:
        report.add(label, section, f"ops {name} (alone)", "", Value.exact(counts[name]))
    report.add(label, section, "ops M + C + g as separate functions", "",
               Value.exact(sum(counts[n] for n in FUNCTIONS[:3])))
    tau = code.dyn.operation_count(["tau"])
    six = code.dyn.model.dof == 6
    report.add(label, section, "ops inverse_dynamics (tau)", "", Value.exact(tau),
               Value.exact(QUOTED_RNEA_6DOF_OPS) if six else None,
               f"general 6-joint RNEA ~850 mul + 740 add, {QUOTED}" if six else "",
               f"< {TARGET_TAU_OPS:,}" if targeted else "",
               (tau < TARGET_TAU_OPS) if targeted else None)
    quoted = {  # Panda numbers of other tools, quoted from the issue
        "mass_matrix": (QUOTED_ADAM_MASS_MATRIX_SX, f"ADAM CasADi M, {QUOTED}", "fewer than ADAM"),
        "inverse_dynamics": (QUOTED_URDF2CASADI_RNEA_SX, f"urdf2casadi RNEA, {QUOTED}", ""),
    }
    for name in FUNCTIONS + ("forward_dynamics",):
        n = getattr(code.casadi_module, name).n_instructions()
        reference, source, target = quoted.get(name, (None, "", "")) if targeted else (None, "", "")
        report.add(label, section, f"SX instructions {name}", "", Value.exact(n),
                   None if reference is None else Value.exact(reference), source, target,
                   (n < reference) if target else None)


class Pinocchio:
    """The reference: Pinocchio's model and data of the robot, and its algorithms."""

    def __init__(self, robot: Robot, joint_names: tuple[str, ...]):
        import pinocchio as pin

        self.pin = pin
        self.model = pinocchio_model(robot, joint_names)
        self.data = self.model.createData()

    def namespace(self, **arrays) -> dict:
        return {"pin": self.pin, "crba": self.pin.crba, "rnea": self.pin.rnea,
                "model": self.model, "data": self.data, **arrays}

    def M(self, q: np.ndarray) -> np.ndarray:
        M = self.pin.crba(self.model, self.data, q).copy()
        return np.triu(M) + np.triu(M, 1).T  # in case only the upper triangle is filled

    def C(self, q, qd):
        return self.pin.computeCoriolisMatrix(self.model, self.data, q, qd).copy()

    def g(self, q):
        return self.pin.computeGeneralizedGravity(self.model, self.data, q).copy()

    def tau(self, q, qd, qdd):
        return self.pin.rnea(self.model, self.data, q, qd, qdd).copy()


def agreement(report: Report, robot: Robot, what: str, ours, reference) -> None:
    diff = float(np.abs(np.asarray(ours) - np.asarray(reference)).max())
    scale = float(np.abs(reference).max())
    report.add(robot.label, "agreement", what, "", Value.exact(diff), Value.exact(scale),
               "max |value|", f"≤ {AGREEMENT:g} relative", diff <= AGREEMENT * max(scale, 1.0),
               ".1e")


def measure_compiled(robot: Robot, code: Generated, ref: Pinocchio | None, settings: Settings,
                     report: Report, state: tuple[np.ndarray, ...]) -> None:
    """Target 3: the compiled functions (CasADi buffer interface) against Pinocchio."""
    label, section, targeted = robot.label, "3 compiled call (CasADi buffer)", robot.targets
    print(f"  {label}: timing compiled calls …", flush=True)
    q, qd, qdd = state
    compiled = {name: compiled_function(code.library, name, inputs) for name, inputs in (
        ("mass_matrix", [q]), ("coriolis_matrix", [q, qd]), ("gravity_vector", [q]),
        ("inverse_dynamics", [q, qd, qdd]))}
    ns = {f"{name}_c": evaluate for name, (evaluate, _, _) in compiled.items()}
    M_c, C_c, g_c, tau_c = (compiled[name][1].copy() for name in FUNCTIONS)
    agreement(report, robot, "compiled M vs NumPy M", M_c, code.numpy_module.mass_matrix(q))
    agreement(report, robot, "compiled tau vs NumPy tau", tau_c,
              code.numpy_module.inverse_dynamics(q, qd, qdd))
    ref_ns = None
    if ref is not None:
        agreement(report, robot, "compiled M vs pin.crba", M_c, ref.M(q))
        agreement(report, robot, "compiled C vs pin.computeCoriolisMatrix", C_c, ref.C(q, qd))
        agreement(report, robot, "compiled g vs pin.computeGeneralizedGravity", g_c, ref.g(q))
        agreement(report, robot, "compiled tau vs pin.rnea", tau_c, ref.tau(q, qd, qdd))
        ref_ns = ref.namespace(q=q, v=qd, a=qdd)

    def pair(ours: str, reference: str) -> list[Value | None]:
        return time_us([Loop(ours, ns, settings.calls),
                        None if ref_ns is None else Loop(reference, ref_ns, settings.calls)],
                       settings.repeats)

    ours_M, ref_M = pair("mass_matrix_c()", "crba(model, data, q)")
    ours_tau, ref_tau = pair("inverse_dynamics_c()", "rnea(model, data, q, v, a)")
    ours_mcg, ref_mcg = pair("mass_matrix_c(); coriolis_matrix_c(); gravity_vector_c()",
                             "crba(model, data, q); pin.computeCoriolisMatrix(model, data, q, v); "
                             "pin.computeGeneralizedGravity(model, data, q)")
    report.add(label, section, "mass_matrix per call", "µs", ours_M, ref_M,
               "measured: pin.crba" if ref_M else "",
               f"≤ {TARGET_CRBA_RATIO:g}× crba" if targeted else "",
               (ours_M.median <= TARGET_CRBA_RATIO * ref_M.median) if targeted else None, ".2f")
    report.add(label, section, "inverse_dynamics per call", "µs", ours_tau, ref_tau,
               "measured: pin.rnea" if ref_tau else "", spec=".2f")
    report.add(label, section, "M + C + g per call (3 calls)", "µs", ours_mcg, ref_mcg,
               "measured: crba + computeCoriolisMatrix + computeGeneralizedGravity"
               if ref_mcg else "", spec=".2f")


def measure_numpy(robot: Robot, code: Generated, ref: Pinocchio | None, settings: Settings,
                  report: Report, states: tuple[np.ndarray, ...]) -> None:
    """Target 4: the generated NumPy functions on a batch against Pinocchio in a Python loop."""
    Q, QD, QDD = states
    N = len(Q)
    label, section, targeted = robot.label, f"4 NumPy ({N:,} states)", robot.targets
    print(f"  {label}: timing NumPy …", flush=True)
    module = code.numpy_module
    ns = {"inverse_dynamics": module.inverse_dynamics, "mass_matrix": module.mass_matrix,
          "Q": Q, "V": QD, "A": QDD, "q": Q[0].copy(), "v": QD[0].copy(), "a": QDD[0].copy()}
    ref_ns = None
    if ref is not None:
        agreement(report, robot, "NumPy batch tau vs pin.rnea", module.inverse_dynamics(Q, QD, QDD),
                  np.array([ref.tau(*s) for s in zip(Q, QD, QDD)]))
        agreement(report, robot, "NumPy batch M vs pin.crba", module.mass_matrix(Q),
                  np.array([ref.M(q) for q in Q]))
        ref_ns = ref.namespace(Q=Q, V=QD, A=QDD, q=ns["q"], v=ns["v"], a=ns["a"])

    def pair(ours: Loop, reference: Loop, clock=time.perf_counter) -> list[Value | None]:
        return time_us([ours, None if ref_ns is None else reference], settings.repeats, clock)

    rnea_loop = Loop("for q, v, a in zip(Q, V, A): rnea(model, data, q, v, a)", ref_ns, units=N)
    ours_batch, ref_batch = pair(Loop("inverse_dynamics(Q, V, A)", ns, units=N), rnea_loop)
    ours_batch_cpu, ref_batch_cpu = pair(Loop("inverse_dynamics(Q, V, A)", ns, units=N),
                                         rnea_loop, time.process_time)
    ours_M_batch, ref_M_batch = pair(Loop("mass_matrix(Q)", ns, units=N),
                                     Loop("for q in Q: crba(model, data, q)", ref_ns, units=N))
    ours_single, ref_single = pair(Loop("inverse_dynamics(q, v, a)", ns, settings.numpy_calls),
                                   Loop("rnea(model, data, q, v, a)", ref_ns, settings.calls))
    report.add(label, section, "inverse_dynamics batch, per sample", "µs", ours_batch,
               ref_batch, "measured: pin.rnea, Python loop" if ref_batch else "",
               f"≤ {1 / TARGET_BATCH_SPEEDUP:.2f} (≥ {TARGET_BATCH_SPEEDUP:g}× faster)"
               if targeted else "",
               (ours_batch.median * TARGET_BATCH_SPEEDUP <= ref_batch.median)
               if targeted else None, ".2f")
    report.add(label, section, "  same, CPU time (process_time)", "µs", ours_batch_cpu,
               ref_batch_cpu, "measured: pin.rnea, Python loop" if ref_batch_cpu else "",
               spec=".2f")
    report.add(label, section, "mass_matrix batch, per sample", "µs", ours_M_batch, ref_M_batch,
               "measured: pin.crba, Python loop" if ref_M_batch else "", spec=".2f")
    report.add(label, section, "inverse_dynamics single state, per call", "µs", ours_single,
               ref_single, "measured: pin.rnea" if ref_single else "", spec=".1f")


def benchmark_robot(robot: Robot, settings: Settings, report: Report, tmp: Path) -> None:
    model = robot.load()
    print(f"{robot.label}: {model.dof} joints; deriving and generating numpy, casadi, c …",
          flush=True)
    code = generate_code(robot, model, tmp, report)
    measure_size(robot, code, report)
    rng = np.random.default_rng(0)
    shape = (settings.batch, model.dof)
    states = (rng.uniform(-np.pi, np.pi, shape), rng.uniform(-2.0, 2.0, shape),
              rng.uniform(-5.0, 5.0, shape))
    ref = Pinocchio(robot, code.dyn.joint_names) if robot.has_pinocchio else None
    measure_compiled(robot, code, ref, settings, report, tuple(s[0].copy() for s in states))
    measure_numpy(robot, code, ref, settings, report, states)
    if robot.targets:
        benchmark_generation(robot, settings, report, tmp)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="fewer calls, one generation run (about a minute)")
    parser.add_argument("--csv", action="store_true",
                        help=f"also write {RESULTS_CSV.relative_to(ROOT)}")
    args = parser.parse_args(argv)
    settings = Settings.choose(args.quick)
    report = Report()
    start = time.perf_counter()
    import pinocchio as pin

    print(f"eomgen {eomgen.__version__}, Python {platform.python_version()}, NumPy "
          f"{np.__version__}, CasADi {ca.__version__}, Pinocchio {pin.__version__}; "
          f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs")
    print(f"settings: {settings}")
    with tempfile.TemporaryDirectory(prefix="eomgen-codegen-speed-") as tmp:
        chosen = robots()
        for robot in chosen:
            benchmark_robot(robot, settings, report, Path(tmp))
    order = [robot.label for robot in chosen]
    report.rows.sort(key=lambda r: (r.section, order.index(r.robot)))  # stable within a robot
    print()
    report.print_table()
    print()
    print("ours/ref below 1: ours smaller or faster. Times: median (min–max) over "
          f"{settings.repeats} repeats; compiled and Pinocchio single calls are loops of "
          f"{settings.calls:,} calls from Python (call overhead included on both sides).")
    print("CPU time (time.process_time) is not inflated by waiting for a CPU on a shared "
          "machine; the targets are judged on wall time (time.perf_counter).")
    print("SX instructions: casadi.Function.n_instructions() of the generated CasADi module "
          "(inputs, outputs and constants included).")
    print("Panda: fingers locked at 0 by eomgen.model.lock_joints and Pinocchio's "
          "buildReducedModel; the CLI, which cannot lock joints, reads a copy of panda.urdf with "
          "the finger joints declared fixed (the same model).")
    for note in report.notes:
        print(note)
    print(f"whole run: {time.perf_counter() - start:.0f} s")
    if args.csv:
        report.write_csv(RESULTS_CSV)
        print(f"wrote {RESULTS_CSV.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
