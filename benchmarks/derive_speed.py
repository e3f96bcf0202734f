"""Derivation speed of eomgen beside sympy.physics.mechanics (Lagrange's and Kane's methods).

Usage::

    python benchmarks/derive_speed.py [--timeout 60] [--quick] [--csv] [--cases planar2,panda]
                                      [--repeat 3] [--clock wall|cpu] [--serial] [--no-peers]

What is measured, per case, each in a fresh Python process (so that SymPy's caches start cold,
a timed-out peer can be killed cleanly, and peak memory is per case):

* **eomgen**: ``derive(model)`` (the straight-line program), then the *expansion*: M, C and g
  as explicit SymPy matrices in ``q``, ``qd``: ``dyn.M``, ``.C``, ``.g`` for teaching-sized
  models, else the program's intermediates substituted into each other (``Program.expand``;
  what ``dyn.M`` was before it became a written-out polynomial or a ``ProgramMatrix`` for
  large models, see docs/teaching.md). "total" is
  their sum; loading the description is not included. The best of ``--repeat`` runs (default
  3) is reported, as timeit does: the others measure the machine's other load. ``ops`` is
  ``dyn.operation_count(("M", "C", "g"))``: SymPy ``count_ops`` over the program that computes
  M, C and g (not the expanded expressions).
* **peers**: the same chain built by hand in ``sympy.physics.mechanics`` (ReferenceFrame, Point,
  RigidBody, dynamicsymbols), then ``LagrangesMethod(L, q).form_lagranges_equations()`` or
  ``KanesMethod(N, q, u, kd_eqs).kanes_equations(bodies, loads)`` and access of ``mass_matrix``
  and ``forcing``. The time includes building the mechanics model (a small share). A peer is
  killed once it has spent ``--timeout`` CPU seconds on the case (wall-clock cap
  1.5 × timeout + 10 s, so that a busy machine neither cuts peers short nor stalls the run) and
  reported as "> T", T being the time it had spent. Once a peer has timed out on a planar chain
  it is not run on the longer planar chains (reported "> T*", with the bound of the shorter
  chain: a longer chain only takes longer).
* **peak MB**: the peak resident set size (``ru_maxrss``) of the measuring process, read with
  ``os.wait4`` for exactly that child: it includes the interpreter with SymPy and eomgen
  imported (about 60-70 MB before any work).

Before the cases, a check derives the planar 2-link chain and a 2-DOF PUMA (joints 3-6 locked
at non-zero angles) with eomgen and with both peers and compares M and the inverse dynamics
M q̈ + C q̇ + g at a random state, so that the peers solve the same problem; it prints
"peer model check ok".

Targets (the foundation issue, for a 2-core machine): Panda (7 DOF) in ≤ 2 s, planar 20-link
chain in ≤ 10 s, peak memory under 1 GB for every case.
"""

from __future__ import annotations

import argparse
import csv
import importlib.metadata
import json
import math
import os
import random
import sys
import sysconfig
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULT_TAG = "RESULT "
READY_TAG = "READY "


# ----------------------------------------------------------------------------------------------
# Cases
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Case:
    name: str
    label: str
    dof: int
    target_s: float | None = None  # time target for eomgen derive + expansion
    family: str = ""  # peers that time out are not run on larger cases of the same family


CASES = (
    Case("planar2", "planar 2-link", 2, family="planar"),
    Case("planar4", "planar 4-link", 4, family="planar"),
    Case("planar8", "planar 8-link", 8, family="planar"),
    Case("planar20", "planar 20-link", 20, 10.0, family="planar"),
    Case("puma5", "PUMA 560 (joints 1-5)", 5),
    Case("panda", "Panda (7 arm joints)", 7, 2.0),
)
QUICK_CASES = ("planar2", "planar4", "panda")
MEMORY_TARGET_MB = 1024.0
PEERS = ("lagrange", "kane")

#: Planar chain: links of length L, mass m, centre of mass mid-link, inertia about the centre of
#: mass I = m L²/12 (a thin rod along x: Iyy = Izz = I, Ixx = 0), revolute joints about z,
#: gravity −g along y.
PLANAR_LENGTH = "1/2"
PLANAR_MASS = 1
GRAVITY = 9.81

PANDA_FINGERS = ("panda_finger_joint1", "panda_finger_joint2")


def planar_numbers():
    import sympy as sp

    L = sp.Rational(PLANAR_LENGTH)
    m = sp.Integer(PLANAR_MASS)
    return L, m, m * L**2 / 12


def planar_model(n: int):
    """The planar n-link chain as an eomgen RobotModel."""
    from eomgen.model import Inertial, Joint, JointType, Link, Transform, build_model, vec3

    L, m, I = planar_numbers()
    links = [Link("base")] + [
        Link(f"link{k}", Inertial(m, (L / 2, 0, 0), ((0, 0, 0), (0, I, 0), (0, 0, I))))
        for k in range(1, n + 1)
    ]
    joints = [
        Joint(f"joint{k}", JointType.REVOLUTE, "base" if k == 1 else f"link{k - 1}", f"link{k}",
              Transform.from_xyz_rpy((0 if k == 1 else L, 0, 0)), vec3((0, 0, 1)))
        for k in range(1, n + 1)
    ]
    return build_model("<benchmark>", f"planar_{n}link", links, joints, gravity=(0, -GRAVITY, 0))


def puma_model(locked: dict[str, float]):
    """The bundled PUMA 560 (standard DH) with the given joints locked."""
    import eomgen
    from eomgen.model import lock_joints
    from eomgen.robots import example_path

    return lock_joints(eomgen.load(example_path("puma560_dh")), locked)


def erd_robots_dir() -> Path | None:
    """The example-robot-data ``robots/`` folder (same lookup as tests/support/__init__.py)."""
    suffix = Path("cmeel.prefix", "share", "example-robot-data", "robots")
    override = os.environ.get("EXAMPLE_ROBOT_DATA_ROBOTS")
    candidates = [Path(override)] if override else []
    try:
        distribution = importlib.metadata.distribution("example-robot-data")
        for file in distribution.files or ():
            parts = Path(file).parts
            for start in range(len(parts) - 2):
                if parts[start:start + 3] == suffix.parts[-3:]:
                    candidates.append(Path(distribution.locate_file(Path(*parts[:start + 3]))))
                    break
    except importlib.metadata.PackageNotFoundError:
        pass
    candidates += [Path(sysconfig.get_paths()[key]) / suffix for key in ("purelib", "platlib")]
    return next((c for c in candidates if c.is_dir()), None)


def panda_model():
    """The Panda arm from example-robot-data, fingers locked at 0 (7 DOF).

    ``eomgen.load`` may refuse the ``<mimic>`` finger joint (older eomgen) or load it with a
    warning (newer): fall back to reading mimic joints as independent, and lock whichever
    finger joints came out movable.
    """
    import eomgen
    from eomgen.errors import UnsupportedError
    from eomgen.model import lock_joints
    from eomgen.parsers.urdf import load_urdf

    robots = erd_robots_dir()
    if robots is None:
        raise RuntimeError("example-robot-data is not installed (pip install example-robot-data)")
    path = robots / "panda_description" / "urdf" / "panda.urdf"
    try:
        model = eomgen.load(path)
    except UnsupportedError:
        model = load_urdf(path, mimic_as_independent=True)
    movable = set(model.joint_names)
    model = lock_joints(model, {name: 0 for name in PANDA_FINGERS if name in movable})
    if model.dof != 7:
        raise RuntimeError(f"expected 7 arm joints, got {model.joint_names}")
    return model


def case_model(name: str):
    if name.startswith("planar"):
        return planar_model(int(name[len("planar"):]))
    if name == "puma5":
        return puma_model({"joint6": 0})
    if name == "panda":
        return panda_model()
    raise KeyError(name)


# ----------------------------------------------------------------------------------------------
# The peers: the same chains in sympy.physics.mechanics
# ----------------------------------------------------------------------------------------------

class PeerSystem:
    """A chain in sympy.physics.mechanics, ready for Lagrange's or Kane's method.

    For Kane's method the generalized speeds are ``u_i = q̇_i`` (kinematic differential
    equations ``q̇_i − u_i = 0``) and each joint's angular velocity is set as ``u_i`` times its
    axis, the usual set-up; for Lagrange's method everything is in ``q̇``.
    """

    def __init__(self, n: int, method: str):
        from sympy.physics.mechanics import Point, ReferenceFrame, dynamicsymbols

        self.method = method
        self.q = list(dynamicsymbols(f"q1:{n + 1}"))
        self.u = list(dynamicsymbols(f"u1:{n + 1}")) if method == "kane" else None
        self.N = ReferenceFrame("N")
        self.O = Point("O")
        self.O.set_vel(self.N, 0)
        self.bodies: list = []
        self.loads: list = []

    def rate(self, i: int):
        """The joint rate symbol of joint i: ``u_i`` (Kane) or ``q̇_i`` (Lagrange)."""
        return self.u[i] if self.method == "kane" else self.q[i].diff()

    def add_body(self, name, point, frame, mass, inertia_dyadic, gravity_vector):
        from sympy.physics.mechanics import RigidBody

        body = RigidBody(name, point, frame, mass, (inertia_dyadic, point))
        if self.method == "lagrange":
            body.potential_energy = -mass * gravity_vector.dot(point.pos_from(self.O))
        else:
            self.loads.append((point, mass * gravity_vector))
        self.bodies.append(body)

    def equations(self):
        """Form the equations of motion; return (mass_matrix, forcing)."""
        from sympy.physics.mechanics import KanesMethod, LagrangesMethod, Lagrangian

        if self.method == "lagrange":
            lm = LagrangesMethod(Lagrangian(self.N, *self.bodies), self.q)
            lm.form_lagranges_equations()
            return lm.mass_matrix, lm.forcing
        kd = [qi.diff() - ui for qi, ui in zip(self.q, self.u)]
        km = KanesMethod(self.N, q_ind=self.q, u_ind=self.u, kd_eqs=kd)
        km.kanes_equations(self.bodies, self.loads)
        return km.mass_matrix, km.forcing


def peer_planar(n: int, method: str) -> PeerSystem:
    """The planar n-link chain written directly, the textbook way (relative joint angles)."""
    from sympy.physics.mechanics import inertia

    L, m, I = planar_numbers()
    system = PeerSystem(n, method)
    N = system.N
    frame, joint = N, system.O
    for i in range(n):
        A = frame.orientnew(f"A{i + 1}", "Axis", (system.q[i], frame.z))
        A.set_ang_vel(frame, system.rate(i) * frame.z)
        centre = joint.locatenew(f"G{i + 1}", L / 2 * A.x)
        centre.v2pt_theory(joint, N, A)
        system.add_body(f"B{i + 1}", centre, A, m, inertia(A, 0, I, I), -GRAVITY * N.y)
        tip = joint.locatenew(f"P{i + 2}", L * A.x)
        tip.v2pt_theory(joint, N, A)
        frame, joint = A, tip
    return system


def peer_from_model(model, method: str) -> PeerSystem:
    """Any eomgen RobotModel (numeric) as a chain of sympy.physics.mechanics frames.

    Per joint, in topological order: a joint frame oriented in the parent link frame by the
    joint origin's rotation (direction cosine matrix ``parent.dcm(joint) = R``), located at the
    origin's translation; then the child link frame, rotated about the joint axis by ``q``
    (revolute) or the child origin moved along it by ``q`` (prismatic). Each link with inertial
    data becomes a RigidBody at its centre of mass.
    """
    import sympy as sp
    from sympy.physics.mechanics import ReferenceFrame, Vector, inertia

    system = PeerSystem(model.dof, method)
    N, O = system.N, system.O
    frames, points = {model.root: N}, {model.root: O}
    index = {name: i for i, name in enumerate(model.joint_names)}

    def vector(frame, values) -> Vector:
        return sum((sp.sympify(v) * e for v, e in zip(values, (frame.x, frame.y, frame.z))),
                   Vector(0))

    for k, joint in enumerate(model.topological_joints):
        parent, origin = frames[joint.parent], points[joint.parent]
        R = sp.Matrix(joint.origin.rotation)
        if R == sp.eye(3):
            J = parent
        else:
            J = ReferenceFrame(f"J{k}")
            J.orient_explicit(parent, R)
            assert parent.dcm(J) == R  # v_parent = R v_joint, as the eomgen model has it
        point = origin.locatenew(f"O{k}", vector(parent, joint.origin.translation))
        point.v2pt_theory(origin, N, parent)
        child, child_point = J, point
        if joint.type.is_movable:
            i = index[joint.name]
            axis = vector(J, joint.axis)
            if joint.type.is_revolute:
                child = J.orientnew(f"C{k}", "Axis", (system.q[i], axis))
                child.set_ang_vel(J, system.rate(i) * axis)
            else:
                child_point = point.locatenew(f"Q{k}", system.q[i] * axis)
                child_point.set_vel(J, system.rate(i) * axis)
                child_point.v1pt_theory(point, N, J)
        frames[joint.child], points[joint.child] = child, child_point
    gravity = vector(N, model.gravity)
    for link in model.links:
        inertial = link.inertial
        if inertial is None or link.name == model.root:
            continue
        if inertial.mass == 0 and all(v == 0 for row in inertial.inertia for v in row):
            continue
        frame, origin = frames[link.name], points[link.name]
        centre = origin.locatenew(f"G_{link.name}", vector(frame, inertial.com))
        centre.v2pt_theory(origin, N, frame)
        (ixx, ixy, ixz), (_, iyy, iyz), (_, _, izz) = inertial.inertia
        dyadic = inertia(frame, ixx, iyy, izz, ixy, iyz, ixz)
        system.add_body(f"B_{link.name}", centre, frame, inertial.mass, dyadic, gravity)
    return system




# ----------------------------------------------------------------------------------------------
# Work done in the child processes
# ----------------------------------------------------------------------------------------------

def _ready() -> None:
    """Tell the parent that set-up is over: the CPU time used so far is not the case's."""
    sys.stdout.write(f"{READY_TAG}{time.process_time()} {time.time()}\n")
    sys.stdout.flush()


def work_eomgen(case: str) -> dict:
    from eomgen.dynamics import derive

    start = time.perf_counter()
    model = case_model(case)
    load_s = time.perf_counter() - start
    _ready()
    start, cpu = time.perf_counter(), time.process_time()
    dyn = derive(model)
    derive_s, derive_cpu = time.perf_counter() - start, time.process_time() - cpu
    start, cpu = time.perf_counter(), time.process_time()
    if dyn.simplified:  # teaching-sized: the reduced textbook matrices
        dyn.M, dyn.C, dyn.g  # noqa: B018  (first access computes them)
    else:  # the substituted program (dyn.M before its written-out or named forms)
        full = dyn.program.expanded()
        for name in ("M", "C", "g"):
            dyn.program.expand(dyn.program.output(name), full)
    expand_s, expand_cpu = time.perf_counter() - start, time.process_time() - cpu
    ops = {name: dyn.operation_count((name,)) for name in ("M", "C", "g")}
    return {"dof": model.dof, "load_s": load_s,
            "wall": {"derive": derive_s, "expand": expand_s},
            "cpu": {"derive": derive_cpu, "expand": expand_cpu},
            "ops": dyn.operation_count(("M", "C", "g")), "ops_M": ops["M"], "ops_C": ops["C"],
            "ops_g": ops["g"], "simplified": dyn.simplified}


def work_peer(case: str, method: str) -> dict:
    import sympy.physics.mechanics  # noqa: F401  (import time is not the peer's derivation)

    if case.startswith("planar"):
        n = int(case[len("planar"):])

        def build():
            return peer_planar(n, method)
    else:
        model = case_model(case)  # loading the description is not timed, as for eomgen

        def build():
            return peer_from_model(model, method)
    _ready()
    start, cpu = time.perf_counter(), time.process_time()
    system = build()
    build_s = time.perf_counter() - start
    mass_matrix, forcing = system.equations()
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    return {"build_s": build_s, "wall": wall, "cpu": cpu, "rows": mass_matrix.rows}


def _peer_numeric(system: PeerSystem, mass_matrix, forcing, q, qd, qdd):
    """Peer M and inverse dynamics τ = M q̈ − forcing at a state, as floats."""
    import sympy as sp

    t = sp.Symbol("t")
    subs = {}
    for i, qi in enumerate(system.q):
        subs[qi.diff(t, 2)] = qdd[i]
        subs[qi.diff(t)] = qd[i]
        subs[qi] = q[i]
        if system.u is not None:
            subs[system.u[i].diff(t)] = qdd[i]
            subs[system.u[i]] = qd[i]
    M = mass_matrix.xreplace(subs).evalf()
    tau = (mass_matrix * sp.Matrix(qdd) - forcing).xreplace(subs).evalf()
    return M, tau


def work_check(quick: bool = False) -> dict:
    """Compare eomgen with both peers on the planar 2-link chain and (unless ``quick``) a 2-DOF
    PUMA, which exercises the generic builder used for the PUMA and Panda cases."""
    from eomgen.dynamics import derive

    rng = random.Random(20240601)
    # joints 1-2 free; 3-6 locked so that the fixed joints turn frames about several axes
    puma_locked = {"joint3": math.pi / 2, "joint4": -math.pi / 2, "joint5": math.pi / 2,
                   "joint6": 0.7}
    checks = {
        "planar2": (planar_model(2), lambda method: peer_planar(2, method)),
        "puma2": (puma_model(puma_locked),
                  lambda method: peer_from_model(puma_model(puma_locked), method)),
    }
    if quick:
        del checks["puma2"]
    worst = 0.0
    for name, (model, build_peer) in checks.items():
        dyn = derive(model, simplify=False)  # numbers only: no need to trig-simplify
        n = model.dof
        q, qd, qdd = ([rng.uniform(-2, 2) for _ in range(n)] for _ in range(3))
        ours = dict(zip(dyn.q + dyn.qd + dyn.qdd, q + qd + qdd))
        M_ours = dyn.M.xreplace(ours).evalf()
        tau_ours = dyn.tau.xreplace(ours).evalf()
        scale = max(1.0, max(abs(float(x)) for x in list(M_ours) + list(tau_ours)))
        for method in PEERS:
            system = build_peer(method)
            M_peer, tau_peer = _peer_numeric(system, *system.equations(), q, qd, qdd)
            error = max(abs(float(a - b)) for a, b in
                        zip(list(M_ours) + list(tau_ours), list(M_peer) + list(tau_peer)))
            if not error <= 1e-9 * scale:
                raise AssertionError(f"{name}, {method}: eomgen and sympy.physics.mechanics "
                                     f"differ by {error:.3g} (M or tau at a random state)")
            worst = max(worst, error / scale)
    return {"cases": sorted(checks), "max_rel_error": worst}


def worker_main(argv: list[str]) -> None:
    warnings.simplefilter("ignore")  # physical-consistency warnings of PUMA link 1, mimic, …
    kind, case = argv[0], argv[1] if len(argv) > 1 else ""
    if kind == "eomgen":
        result = work_eomgen(case)
    elif kind in PEERS:
        result = work_peer(case, kind)
    elif kind == "check":
        result = work_check(quick=case == "quick")
    else:
        raise SystemExit(f"unknown worker {kind}")
    sys.stdout.write(RESULT_TAG + json.dumps(result) + "\n")
    sys.stdout.flush()


# ----------------------------------------------------------------------------------------------
# Running children with a timeout and per-child peak memory
# ----------------------------------------------------------------------------------------------

@dataclass
class Outcome:
    """What a worker process gave: its result (None unless ``status == "ok"``), its peak RSS
    [MB] and, for a timed-out worker, the CPU time it had spent on the case when killed."""

    result: dict | None
    status: str  # "ok", "timeout", "error", "skipped", "not run"
    peak_mb: float | None = None
    cpu_at_kill: float | None = None
    wall_at_kill: float | None = None
    message: str = ""


class Child:
    """One worker process, reaped with ``os.wait4`` to get its own peak RSS.

    The timeout counts the CPU seconds the worker has spent on the case (after its READY line,
    read from ``/proc/<pid>/stat``), so that other load on the machine does not cut a peer
    short; a wall-clock cap of ``1.5 × timeout + 10`` s (from the start) bounds the run anyway.
    Where ``/proc`` is missing the timeout is on wall-clock time since READY.
    """

    def __init__(self, kind: str, case: str, timeout: float):
        import subprocess

        self.timeout = timeout
        self.out = tempfile.TemporaryFile()
        self.err = tempfile.TemporaryFile()
        env = dict(os.environ)
        for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            env.setdefault(name, "1")  # no BLAS threads spinning beside the measured one
        self.start = time.time()
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(__file__).resolve()), "--worker", kind, case],
            stdout=self.out, stderr=self.err, stdin=subprocess.DEVNULL, env=env)
        self.ready: tuple[float, float] | None = None  # (CPU s, epoch s) at the READY line
        self.outcome: Outcome | None = None

    def _lines(self) -> list[str]:
        # pread: the child shares the file offset, which must not move under it
        size = os.fstat(self.out.fileno()).st_size
        return os.pread(self.out.fileno(), size, 0).decode(errors="replace").splitlines()

    def _spent(self) -> tuple[float, float]:
        """(CPU seconds, wall seconds) spent on the case so far."""
        if self.ready is None:
            for line in self._lines():
                if line.startswith(READY_TAG):
                    cpu, wall = line[len(READY_TAG):].split()
                    self.ready = (float(cpu), float(wall))
        if self.ready is None:
            return 0.0, 0.0
        wall = time.time() - self.ready[1]
        try:
            with open(f"/proc/{self.proc.pid}/stat") as handle:
                fields = handle.read().rsplit(")", 1)[1].split()
            cpu = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK") - self.ready[0]
        except (OSError, IndexError, ValueError):
            cpu = wall
        return cpu, wall

    def poll(self) -> bool:
        """Reap the child if it ended (or kill it past its timeout); True when done."""
        if self.outcome is not None:
            return True
        pid, status, usage = os.wait4(self.proc.pid, os.WNOHANG)
        spent = None
        if pid == 0:
            spent = self._spent()
            if spent[0] < self.timeout and time.time() - self.start < 1.5 * self.timeout + 10:
                return False
            self.proc.kill()
            pid, status, usage = os.wait4(self.proc.pid, 0)
        self.proc.returncode = os.waitstatus_to_exitcode(status)
        peak_mb = usage.ru_maxrss / 1024  # kilobytes on Linux
        lines = self._lines()
        results = [l[len(RESULT_TAG):] for l in lines if l.startswith(RESULT_TAG)]
        if spent is not None:
            self.outcome = Outcome(None, "timeout", peak_mb, cpu_at_kill=spent[0],
                                   wall_at_kill=spent[1])
        elif self.proc.returncode != 0 or not results:
            self.err.seek(0)
            tail = self.err.read().decode(errors="replace").strip().splitlines()[-3:]
            self.outcome = Outcome(None, "error", peak_mb, message=" | ".join(tail))
        else:
            self.outcome = Outcome(json.loads(results[-1]), "ok", peak_mb)
        self.out.close()
        self.err.close()
        return True


def run_children(specs: list[tuple[str, str, float]], parallel: bool) -> list[Outcome]:
    """Run workers (kind, case, timeout), all at once or one after the other."""
    outcomes: list[Outcome] = []
    batches = [specs] if parallel else [[s] for s in specs]
    for batch in batches:
        children = [Child(*spec) for spec in batch]
        while not all(child.poll() for child in children):
            time.sleep(0.02)
        outcomes += [child.outcome for child in children]
    return outcomes


def best_of(outcomes: list[Outcome], clock: str) -> Outcome:
    """The fastest successful eomgen measurement on ``clock``, with the largest peak memory of
    all runs and every run's total (on that clock) recorded."""
    ok = [o for o in outcomes if o.status == "ok"]
    if not ok:
        return outcomes[0]

    def total(o):
        return o.result[clock]["derive"] + o.result[clock]["expand"]

    best = min(ok, key=total)
    peaks = [o.peak_mb for o in outcomes if o.peak_mb is not None]
    return Outcome({**best.result, "runs": [total(o) for o in ok]}, "ok",
                   max(peaks) if peaks else None)


# ----------------------------------------------------------------------------------------------
# Report
# ----------------------------------------------------------------------------------------------

@dataclass
class PeerTime:
    """A peer's time on one clock: exact, or a lower bound (timed out / not run)."""

    seconds: float | None
    bound: bool = False
    skipped: bool = False


def peer_time(outcome: Outcome, clock: str, timeout: float) -> PeerTime:
    if outcome.status == "ok":
        return PeerTime(outcome.result[clock])
    if outcome.status in ("timeout", "skipped"):
        return PeerTime(outcome.wall_at_kill if clock == "wall" else outcome.cpu_at_kill,
                        bound=True, skipped=outcome.status == "skipped")
    return PeerTime(None)


def fmt_s(x: float | None) -> str:
    if x is None:
        return "—"
    return f"{x:.2f}" if x < 100 else f"{x:.0f}"


def peer_cell(t: PeerTime) -> str:
    if t.seconds is None:
        return "—"
    if t.bound:
        return f"> {t.seconds:.0f}" + ("*" if t.skipped else "")
    return fmt_s(t.seconds)


def ratio_cell(t: PeerTime, ours: float | None) -> str:
    if ours is None or ours <= 0 or t.seconds is None:
        return "—"
    return ("> " if t.bound else "") + f"{t.seconds / ours:.1f}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--timeout", type=float, default=None,
                        help="CPU seconds a peer may spend on a case (default 60; 5 with "
                             "--quick); wall-clock cap 1.5 × timeout + 10 s")
    parser.add_argument("--quick", action="store_true",
                        help=f"only {', '.join(QUICK_CASES)}, with a short peer timeout")
    parser.add_argument("--cases", default=None,
                        help="comma-separated case names: " + ", ".join(c.name for c in CASES))
    parser.add_argument("--csv", action="store_true",
                        help="also write benchmarks/results/derive_speed.csv")
    parser.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                        help="times in the table, targets and ratios: wall clock (default) or "
                             "the process's CPU time (steadier on a shared machine); the CSV "
                             "has both")
    parser.add_argument("--serial", action="store_true",
                        help="run the two peers of a case one after the other (default: side by "
                             "side, one per core)")
    parser.add_argument("--repeat", type=int, default=None,
                        help="eomgen measurements per case, best kept (default 3; 2 with --quick)")
    parser.add_argument("--no-peers", action="store_true", help="measure eomgen only")
    parser.add_argument("--eomgen-timeout", type=float, default=300.0,
                        help="seconds allowed to an eomgen measurement (default 300)")
    args = parser.parse_args(argv)
    timeout = args.timeout if args.timeout is not None else (5.0 if args.quick else 60.0)
    repeat = max(1, args.repeat if args.repeat is not None else (2 if args.quick else 3))
    if args.cases:
        wanted = args.cases.split(",")
        unknown = sorted(set(wanted) - {c.name for c in CASES})
        if unknown:
            parser.error(f"unknown cases {unknown}")
    else:
        wanted = list(QUICK_CASES) if args.quick else [c.name for c in CASES]
    cases = [c for c in CASES if c.name in wanted]

    run_start = time.perf_counter()
    print(f"eomgen derivation speed — Python {sys.version.split()[0]}, "
          f"sympy {importlib.metadata.version('sympy')}, "
          f"eomgen {importlib.metadata.version('eomgen')}, {os.cpu_count()} CPUs; "
          f"{args.clock} clock; peer timeout {timeout:g} s; eomgen best of {repeat}")
    load = os.getloadavg()[0]
    if load > 0.5:
        print(f"note: load average {load:.1f} at the start: other processes share the CPUs and "
              "wall-clock times may be inflated (--clock cpu is steadier; the CSV has both)")
    if not args.no_peers:
        (check,) = run_children([("check", "quick" if args.quick else "", max(120.0, timeout))],
                                parallel=False)
        if check.status != "ok":
            print(f"peer model check FAILED ({check.status}): {check.message}")
            return 1
        print(f"peer model check ok ({', '.join(check.result['cases'])}: M and M q̈ + C q̇ + g "
              f"agree with Lagrange and Kane, max rel. error "
              f"{check.result['max_rel_error']:.1e})")

    rows = []
    #: peer → family → the timed-out outcome on a smaller case of that family
    timed_out: dict[str, dict[str, Outcome]] = {peer: {} for peer in PEERS}
    for case in cases:
        ours = best_of(run_children([("eomgen", case.name, args.eomgen_timeout)] * repeat,
                                    parallel=False), args.clock)
        peers: dict[str, Outcome] = {}
        to_run = []
        for peer in PEERS:
            if args.no_peers:
                peers[peer] = Outcome(None, "not run")
            elif case.family in timed_out[peer]:
                smaller = timed_out[peer][case.family]
                peers[peer] = Outcome(None, "skipped", cpu_at_kill=smaller.cpu_at_kill,
                                      wall_at_kill=smaller.wall_at_kill)
            else:
                to_run.append(peer)
        outcomes = run_children([(peer, case.name, timeout) for peer in to_run],
                                parallel=not args.serial)
        peers.update(zip(to_run, outcomes))
        for peer, outcome in peers.items():
            if outcome.status == "timeout" and case.family:
                timed_out[peer][case.family] = outcome
        rows.append(make_row(case, ours, peers, timeout, args.clock))
        print(f"  {case.label}: eomgen {rows[-1]['total_s']} s ({ours.status})"
              + ("" if args.no_peers else
                 "; " + ", ".join(f"{p} {rows[-1][p + '_s']} s" for p in PEERS)), flush=True)

    print()
    print_table(rows)
    print()
    clock = "wall-clock" if args.clock == "wall" else "CPU"
    print(f"Seconds of {clock} time, each measurement in a fresh process (eomgen: best of "
          f"{repeat}). total = derive + expand (M, C, g as explicit expressions). "
          "ops = operation count of the straight-line program for M, C, g. peak MB = peak RSS "
          "of the eomgen process (interpreter and imports included). Peers: "
          "sympy.physics.mechanics, model construction + equations + mass_matrix/forcing. "
          + f"'> T' = stopped after T s, at the timeout ({timeout:g} CPU s on the case, or a "
          "wall-clock cap); '*' = not run, it timed out on a shorter chain (bound from there). "
          "Ratio = peer time / eomgen total.")
    if not args.no_peers and not args.serial:
        print("The two peers of a case ran side by side (one per core); eomgen ran alone.")
    other = "cpu" if args.clock == "wall" else "wall"
    targets = [f"{row['case']} {row[other + '_total_s']} s (target {row['target'].split(',')[0]})"
               for row, case in zip(rows, cases) if case.target_s and row[other + "_total_s"]]
    if targets:
        print(f"eomgen on the {'CPU' if other == 'cpu' else 'wall'} clock: " + "; ".join(targets)
              + ".")
    print(f"Whole run: {time.perf_counter() - run_start:.0f} s.")
    if args.csv:
        path = HERE / "results" / "derive_speed.csv"
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        print(f"Wrote {path.relative_to(HERE.parent)}")
    return 0 if all(row["met"] == "yes" for row in rows) else 2


def make_row(case: Case, ours: Outcome, peers: dict[str, Outcome], timeout: float,
             clock: str) -> dict:
    r = ours.result or {}
    ok = ours.status == "ok"
    derive_s = r[clock]["derive"] if ok else None
    expand_s = r[clock]["expand"] if ok else None
    total = derive_s + expand_s if ok else None
    peak = ours.peak_mb
    target = (f"≤ {case.target_s:g} s, " if case.target_s else "") + "< 1 GB"
    if not ok:
        met = f"no ({ours.status}{': ' + ours.message if ours.message else ''})"
    else:
        met = "yes" if (peak is not None and peak < MEMORY_TARGET_MB
                        and (case.target_s is None or total <= case.target_s)) else "no"
    times = {peer: peer_time(outcome, clock, timeout) for peer, outcome in peers.items()}
    row = {
        "case": case.label, "dof": case.dof, "derive_s": fmt_s(derive_s),
        "expand_s": fmt_s(expand_s), "total_s": fmt_s(total), "target": target, "met": met,
        "ops": r.get("ops", "—"), "peak_mb": f"{peak:.0f}" if peak is not None else "—",
        **{f"{peer}_s": peer_cell(t) for peer, t in times.items()},
        **{f"{peer}_ratio": ratio_cell(t, total) for peer, t in times.items()},
    }
    # CSV only: the other clock, every run, memory of the peers, operation counts by output
    other = "cpu" if clock == "wall" else "wall"
    row.update({
        "clock": clock,
        f"{other}_derive_s": fmt_s(r[other]["derive"]) if ok else "",
        f"{other}_expand_s": fmt_s(r[other]["expand"]) if ok else "",
        f"{other}_total_s": fmt_s(r[other]["derive"] + r[other]["expand"]) if ok else "",
        f"eomgen_runs_{clock}_s": " ".join(f"{x:.2f}" for x in r.get("runs", [])),
        **{f"{peer}_{other}_s": peer_cell(peer_time(o, other, timeout)) if o.status in
           ("ok", "timeout", "skipped") else "" for peer, o in peers.items()},
        **{f"{peer}_peak_mb": f"{o.peak_mb:.0f}" if o.peak_mb is not None else ""
           for peer, o in peers.items()},
        "load_s": fmt_s(r.get("load_s")), "ops_M": r.get("ops_M", ""),
        "ops_C": r.get("ops_C", ""), "ops_g": r.get("ops_g", ""), "peer_timeout_s": f"{timeout:g}",
    })
    return row


TABLE_COLUMNS = (
    ("case", "case"), ("dof", "DOF"), ("derive_s", "derive s"), ("expand_s", "expand s"),
    ("total_s", "total s"), ("target", "target"), ("met", "met?"), ("ops", "ops"),
    ("peak_mb", "peak MB"), ("lagrange_s", "Lagrange s"), ("kane_s", "Kane s"),
    ("lagrange_ratio", "Lagrange/eomgen"), ("kane_ratio", "Kane/eomgen"),
)


def print_table(rows: list[dict]) -> None:
    cells = [[str(row[key]) for key, _ in TABLE_COLUMNS] for row in rows]
    heads = [title for _, title in TABLE_COLUMNS]
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(heads)]
    numeric = {i for i, (key, _) in enumerate(TABLE_COLUMNS) if key not in ("case", "target", "met")}

    def line(values):
        return "| " + " | ".join(v.rjust(w) if i in numeric else v.ljust(w)
                                 for i, (v, w) in enumerate(zip(values, widths))) + " |"

    print(line(heads))
    print("|" + "|".join(("-" * (w + 1) + ":") if i in numeric else ("-" * (w + 2))
                         for i, w in enumerate(widths)) + "|")
    for c in cells:
        print(line(c))


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        worker_main(sys.argv[2:])
    else:
        sys.exit(main())
