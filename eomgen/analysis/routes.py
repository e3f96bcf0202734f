"""Every way eomgen's dynamics can be evaluated, behind one interface: :class:`Route`.

A route evaluates inverse dynamics ``tau(q, qd, qdd)`` and the mass matrix ``M(q)`` for a
batch of states (arrays of shape (N, n), results (N, n) and (N, n, n)); a route that takes one
state per call loops over the batch, so that its time per state includes the call overhead a
user pays.

=========================  =======  ====================================================
route                      dtype    what is called
=========================  =======  ====================================================
NumPy, one state           float64  ``<robot>_numpy.py``, once per state
NumPy, batch               float64  ``<robot>_numpy.py`` on the whole (N, n) batch
NumPy float32, batch       float32  the same program printed over float32 arrays
                                    (:func:`compile_batch`; constants rounded to float32)
Python floats, one state   float64  the program printed over Python floats with ``math``
                                    (:func:`compile_scalar`; what ``eomgen simulate`` uses)
CasADi SX, one state       float64  ``<robot>_casadi.py``'s ``casadi.Function``
CasADi SX, map             float64  the same, ``Function.map(N)`` over the batch
C (CasADi), one state      float64  the compiled ``lib<robot>_casadi.so`` via ``casadi.external``
C (CasADi), map            float64  the same, mapped over the batch
C (ctypes), one state      float64  the same library's C functions called through ctypes
                                    (no CasADi call layer: the speed of the C code itself
                                    plus about a microsecond of ctypes overhead)
C extension, one state     float64  the compiled ``<robot>_fast`` module (``--backend fast``)
C extension, batch         float64  the same on the whole batch (the loop runs in C)
RNEA (eomgen.numeric)      float64  :func:`eomgen.numeric.rnea` and ``M_crba``
Pinocchio                  float64  plain ``pin.rnea(model, data, q, qd, qdd)`` and
                                    ``pin.crba(model, data, q)`` on the model built by
                                    :mod:`~eomgen.numeric.pinocchio` (the joint
                                    reordering only where its order differs from eomgen's)
=========================  =======  ====================================================

The C routes exist when a C compiler is found, Pinocchio when it is installed. Only the
program routes offer float32: the generated NumPy module casts its inputs to float64, and
CasADi and Pinocchio (from Python) compute in double precision.
"""

from __future__ import annotations

import ctypes
import importlib.util
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np
import sympy as sp

from ..codegen import available_backends, make_job
from ..common.compiler import c_compiler
from ..dynamics import Dynamics, derive
from ..model import RobotModel
from ..common.progress import plural
from ..numeric import M_crba, numeric_model, rnea
from ..numeric.pinocchio import plain_calls, to_pinocchio
from ..outputs import INVERSE, MASS
from ..codegen.backends.casadi_backend import library_name
from ..codegen.backends.numpy_backend import NumPyModulePrinter
from ..symbolic.evaluate import FloatPrinter
from ..symbolic.printing import program_function
from ..symbolic.program import Program

# ----------------------------------------------------------------------------------------------
# Printing a program for scalars and for batches of a given dtype
# ----------------------------------------------------------------------------------------------


class _BatchPrinter(NumPyModulePrinter):
    """NumPy code over arrays of one dtype: every literal wrapped in ``_F`` (that dtype)."""

    def _literal(self, value: float) -> str:
        return f"_F({value!r})"

    def _print_Pi(self, expr):
        return "_F(np.pi)"


def compile_scalar(program: Program, inputs: Sequence[sp.Symbol], outputs: Sequence[str],
                   fixed: dict | None = None) -> Callable[..., tuple[list[float], ...]]:
    """``f(*floats) -> (flat list of output 1, …)``: the program over Python floats.

    ``fixed`` maps symbols to constants substituted before printing (e.g. ``qdd = 0`` for the
    bias forces, which shortens the program). Outputs are flat row-major lists. The printed code
    is our own program, executed in a namespace holding ``math``'s functions only.
    """
    printer = FloatPrinter()
    functions = {f: getattr(math, f) for f in ("sin", "cos", "tan", "sqrt", "pi")}
    return program_function(program, inputs, printer, functions, outputs, fixed, flat=True,
                            filename="<eomgen scalar program>")


def compile_batch(program: Program, inputs: Sequence[sp.Symbol], outputs: Sequence[str],
                  dtype=np.float64) -> Callable[..., tuple[np.ndarray, ...]]:
    """``f(*columns) -> (array (N, rows, cols) per output)``: the program over arrays of
    ``dtype`` (each input a column of shape (N,)), every literal rounded to ``dtype``. With
    float32 this is the float32 evaluation of exactly the program the generators print."""
    printer = _BatchPrinter({"fully_qualified_modules": True, "standard": "python3"})
    raw = program_function(program, inputs, printer, {"np": np, "_F": np.dtype(dtype).type},
                           outputs, filename="<eomgen batch program>")
    shapes = [program.output(n).shape for n in outputs]

    def evaluate(*columns) -> tuple[np.ndarray, ...]:
        columns = [np.asarray(c, dtype=dtype) for c in columns]
        size = columns[0].shape[0] if columns else 1
        results = []
        for value, shape in zip(raw(*columns), shapes):
            out = np.empty((size,) + shape, dtype=dtype)
            for r in range(shape[0]):
                for c in range(shape[1]):
                    out[:, r, c] = value[r][c]
            results.append(out)
        return tuple(results)

    return evaluate


# ----------------------------------------------------------------------------------------------
# Routes
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Route:
    """One way of evaluating the dynamics.

    ``tau(q, qd, qdd)`` takes (N, n) arrays and returns (N, n); ``M(q)`` takes (N, n) and
    returns (N, n, n); results are in the route's ``dtype``.
    """

    name: str
    dtype: str
    batch: bool
    tau: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    M: Callable[[np.ndarray], np.ndarray]
    note: str = ""


def _per_state(function, n_out_shape):
    def run(*arrays):
        size = arrays[0].shape[0]
        out = np.empty((size,) + n_out_shape)
        for k in range(size):
            out[k] = function(*(a[k] for a in arrays))
        return out

    return run


def _import(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # our own generated module
    return module


def numeric_only(model: RobotModel) -> RobotModel:
    """``model`` with every parameter replaced by its value."""
    return model.with_numeric_parameters() if model.parameters else model


def build_routes(model: RobotModel, workdir: Path, dynamics: Dynamics | None = None,
                 progress: Callable[[str], None] = lambda _: None,
                 skip: Iterable[str] = ()) -> list[Route]:
    """Every available route for ``model`` (parameters at their values).

    Parameters
    ----------
    model:
        The robot.
    workdir:
        Folder for the generated modules and the compiled library; must outlive the routes.
    dynamics:
        ``derive(model, outputs=("M", "tau"))`` when already at hand.
    skip:
        Route names to leave out.
    """
    model = numeric_only(model)
    if dynamics is None:
        progress(f"deriving M and tau of {model.name} ({plural(model.dof, 'joint')})")
        dynamics = derive(model, outputs=("M", "tau"), simplify=False)
    n = model.dof
    skip = set(skip)
    tau_name, M_name = INVERSE.function, MASS.function
    job = make_job(dynamics, (INVERSE.symbol, MASS.symbol))
    registry = available_backends()
    chosen = ["numpy", "casadi"] + (["c", "fast"] if c_compiler() else [])
    files = []
    for backend in chosen:
        progress(f"generating the {backend} code")
        files += registry[backend].generate(job)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    paths = {}
    for f in files:
        path = workdir / f.name
        if isinstance(f.content, bytes):
            path.write_bytes(f.content)
        else:
            path.write_text(f.content, encoding="utf-8")
        paths[f.name] = path
    routes: list[Route] = []

    def suffix(backend: str) -> str:
        return registry[backend].config().suffix

    numpy_module = _import(paths[job.stem + suffix("numpy")], f"_eomgen_bench_{job.stem}_numpy")
    routes.append(Route("NumPy, one state", "float64", False,
                        _per_state(getattr(numpy_module, tau_name), (n,)),
                        _per_state(getattr(numpy_module, M_name), (n, n)),
                        "generated <robot>_numpy.py, called per state"))
    routes.append(Route("NumPy, batch", "float64", True,
                        getattr(numpy_module, tau_name), getattr(numpy_module, M_name),
                        "generated <robot>_numpy.py on the (N, n) batch"))

    d = dynamics
    tau32 = compile_batch(d.program, d.q + d.qd + d.qdd, ["tau"], np.float32)
    M32 = compile_batch(d.program, d.q, ["M"], np.float32)
    routes.append(Route(
        "NumPy float32, batch", "float32", True,
        lambda q, qd, qdd: tau32(*np.asarray(q, np.float32).T, *np.asarray(qd, np.float32).T,
                                 *np.asarray(qdd, np.float32).T)[0][:, :, 0],
        lambda q: M32(*np.asarray(q, np.float32).T)[0],
        "the same program over float32 arrays"))

    tau_scalar = compile_scalar(d.program, d.q + d.qd + d.qdd, ["tau"])
    M_scalar = compile_scalar(d.program, d.q, ["M"])
    routes.append(Route(
        "Python floats, one state", "float64", False,
        _per_state(lambda q, qd, qdd: tau_scalar(*q.tolist(), *qd.tolist(), *qdd.tolist())[0],
                   (n,)),
        _per_state(lambda q: np.reshape(M_scalar(*q.tolist())[0], (n, n)), (n, n)),
        "the program printed over Python floats (math)"))

    casadi_stem = job.stem + suffix("casadi").removesuffix(".py")
    casadi_module = _import(paths[casadi_stem + ".py"], f"_eomgen_bench_{job.stem}_casadi")
    routes += _casadi_routes("CasADi SX", getattr(casadi_module, tau_name),
                             getattr(casadi_module, M_name), n,
                             "casadi.Function (SX virtual machine)")
    library = paths.get(library_name(job.stem))
    if library is not None:
        import casadi as ca  # optional dependency: only where a CasADi library was built

        routes += _casadi_routes("C (CasADi)", ca.external(tau_name, str(library)),
                                 ca.external(M_name, str(library)), n,
                                 "compiled lib<robot>_casadi.so via casadi.external")
        shared = ctypes.CDLL(str(library))
        tau_c = CFunction(shared, tau_name)
        M_c = CFunction(shared, M_name)
        routes.append(Route("C (ctypes), one state", "float64", False,
                            _per_state(tau_c, (n,)),
                            _per_state(lambda q: M_c(q).reshape(n, n), (n, n)),
                            "compiled lib<robot>_casadi.so called through ctypes"))

    fast_stem = job.stem + suffix("fast")
    fast = [p for name, p in paths.items() if name.startswith(fast_stem + ".")
            and not name.endswith(".c")]
    if fast:
        fast_module = _import(fast[0], fast_stem)
        routes.append(Route("C extension (fast), one state", "float64", False,
                            _per_state(getattr(fast_module, tau_name), (n,)),
                            _per_state(getattr(fast_module, M_name), (n, n)),
                            "generated <robot>_fast module (--backend fast), called per state"))
        routes.append(Route("C extension (fast), batch", "float64", True,
                            getattr(fast_module, tau_name), getattr(fast_module, M_name),
                            "generated <robot>_fast module on the (N, n) batch (loop in C)"))

    nm = numeric_model(model)
    routes.append(Route("RNEA (eomgen.numeric)", "float64", False,
                        _per_state(lambda q, qd, qdd: rnea(nm, q, qd, qdd), (n,)),
                        _per_state(lambda q: M_crba(nm, q), (n, n)),
                        "eomgen.numeric.rnea; M by its composite-rigid-body algorithm"))
    try:
        pm = to_pinocchio(model)
    except ImportError:
        progress("Pinocchio is not installed: no Pinocchio route")
    else:
        routes.append(pinocchio_route(pm, n))
    return [r for r in routes if r.name not in skip]


def pinocchio_route(pm, n: int) -> Route:
    """Pinocchio as a user would call it (:func:`eomgen.numeric.pinocchio.plain_calls`): the
    plain public calls on arrays in Pinocchio's joint order, or, when that order is not
    eomgen's, with the reordering a user would need as part of the route (its note says so)."""
    rnea_pin, crba_pin, note = plain_calls(pm, n)
    return Route("Pinocchio", "float64", False, _per_state(rnea_pin, (n,)),
                 _per_state(crba_pin, (n, n)), note)


class CFunction:
    """A function of a CasADi-generated C library, called through ctypes.

    Uses the C API CasADi generates: ``name(arg, res, iw, w, mem)``, ``name_work`` for the work
    sizes and ``name_sparsity_in/out`` (compressed column storage) for the shapes. Inputs are
    the function's vector inputs in order; the output is returned dense (row-major, flat).
    """

    def __init__(self, library: ctypes.CDLL, name: str):
        c_int, c_ll, c_double = ctypes.c_int, ctypes.c_longlong, ctypes.c_double
        self._f = getattr(library, name)
        self._f.restype = c_int
        sizes = [c_ll() for _ in range(4)]
        work = getattr(library, name + "_work")
        work.restype = c_int
        work(*(ctypes.byref(s) for s in sizes))
        sz_arg, sz_res, sz_iw, sz_w = (s.value for s in sizes)
        n_in = getattr(library, name + "_n_in")
        n_in.restype = c_ll
        sparsity_in = getattr(library, name + "_sparsity_in")
        sparsity_out = getattr(library, name + "_sparsity_out")
        for f in (sparsity_in, sparsity_out):
            f.restype = ctypes.POINTER(c_ll)
            f.argtypes = [c_ll]
        self._inputs = []
        for i in range(n_in()):
            rows, cols = sparsity_in(i)[0], sparsity_in(i)[1]
            self._inputs.append(np.zeros(rows * cols))
        sp_out = sparsity_out(0)
        rows, cols = sp_out[0], sp_out[1]
        if sp_out[2] == 1:  # compact form {rows, cols, 1}: dense, column-major
            colind = [c * rows for c in range(cols + 1)]
            row = [r for _ in range(cols) for r in range(rows)]
        else:  # {rows, cols, colind[0..cols], row[0..nnz-1]}
            colind = [sp_out[2 + c] for c in range(cols + 1)]
            row = [sp_out[3 + cols + k] for k in range(colind[-1])]
        nnz = colind[-1]
        self._scatter = np.array([row[k] * cols + c for c in range(cols)
                                  for k in range(colind[c], colind[c + 1])], dtype=int)
        self._shape = rows * cols
        self._buffer = np.zeros(max(nnz, 1))
        pointer = ctypes.POINTER(c_double)
        self._arg = (pointer * max(sz_arg, 1))(*[a.ctypes.data_as(pointer) for a in self._inputs])
        self._res = (pointer * max(sz_res, 1))(self._buffer.ctypes.data_as(pointer))
        self._iw = (c_ll * max(sz_iw, 1))()
        self._w = (c_double * max(sz_w, 1))()
        self._name = name

    def __call__(self, *vectors) -> np.ndarray:
        for buffer, v in zip(self._inputs, vectors):
            buffer[:] = v
        if self._f(self._arg, self._res, self._iw, self._w, 0):
            raise RuntimeError(f"{self._name} failed")
        out = np.zeros(self._shape)
        out[self._scatter] = self._buffer[:len(self._scatter)]
        return out


def _casadi_routes(label: str, tau_f, M_f, n: int, note: str) -> list[Route]:
    def tau_one(q, qd, qdd):
        return np.asarray(tau_f(q, qd, qdd)).ravel()

    def M_one(q):
        return np.asarray(M_f(q))

    maps: dict = {}

    def mapped(function, size):
        key = (id(function), size)
        if key not in maps:
            maps[key] = function.map(size)
        return maps[key]

    def tau_map(q, qd, qdd):
        out = mapped(tau_f, q.shape[0])(q.T, qd.T, qdd.T)
        return np.asarray(out).T

    def M_map(q):
        out = np.asarray(mapped(M_f, q.shape[0])(q.T))  # (n, n N): the N matrices side by side
        return out.reshape(n, q.shape[0], n).transpose(1, 0, 2)

    return [Route(f"{label}, one state", "float64", False, _per_state(tau_one, (n,)),
                  _per_state(M_one, (n, n)), note),
            Route(f"{label}, map", "float64", True, tau_map, M_map, note + ", Function.map(N)")]


__all__ = ["Route", "build_routes", "compile_scalar", "compile_batch", "numeric_only"]
