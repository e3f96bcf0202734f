"""Fast backend: ``<robot>_fast.c``, a CPython extension module in C, and where a C compiler and
Python's headers are found, the compiled module ``<robot>_fast<EXT_SUFFIX>`` (e.g.
``ur5_fast.cpython-311-x86_64-linux-gnu.so``) that ``import ur5_fast`` loads.

The module exports the same names as the NumPy module (``JOINT_NAMES``, ``NV``, ``PARAMETERS``,
the functions of :data:`eomgen.outputs.OUTPUTS`, ``IllConditionedWarning``), each function
taking one state ``(NV,)`` or a batch ``(N, NV)`` and looping over the batch in C (the long
kernels four states at a time on SIMD vectors, :data:`FMA_CLONE_OPERATIONS`). It is the route for one state at a time
from Python: a call costs the C arithmetic plus a few hundred nanoseconds of argument parsing
and one NumPy array allocation (no CasADi call layer, no ctypes). The composed
``forward_dynamics`` and ``constrained_forward_dynamics`` are solved in C by one shared Cholesky
routine on stack arrays (docs/contact.md has the constrained solve and its errors).

Printer: SymPy's :class:`~sympy.printing.c.C99CodePrinter` with exact float literals and
small integer powers written as products. Template: ``templates/fast/module.c.jinja``.

Build: the long kernels are cut out of the source into translation units of their own
(:mod:`.fast_units`), compiled in parallel and cached by content (:func:`compile_module`).
"""

from __future__ import annotations

import sysconfig
import warnings
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Callable

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.precedence import PRECEDENCE

from ...common.compiler import c_compiler, compile_jobs, linked_library, shared_library
from ...common import progress as progress_lines
from ...common.output import GeneratedFile
from ..job import Job
from ..registry import Loaded, register
from ...outputs import (CONSTRAINED_DERIVATIVES, CONSTRAINED_FORWARD, CONSTRAINED_PARTIALS,
                       FORWARD, INPUT_SIZES, PARALLEL_INVERSE,
                       TASK_SPACE, composition_names, constrained_names, exported,
                       parallel_names, task_space_names)
from ...symbolic.printing import FloatLiteralMixin, renamed
from ...common.templating import TEMPLATES_DIR, render
from .common import (import_file, parallel_indices, positional, printed_once,
                     warning_exports)
from .fast_units import UNIT_RUNTIME, kernel_signature, split_source

#: The fixed C runtime every generated module includes parts of: real C files (compiled and
#: warning-checked on their own by tests/backends/test_fast_runtime_c.py), by the name the template
#: gives their text (``runtime.cholesky`` ...).
RUNTIME_DIR = TEMPLATES_DIR / "fast" / "runtime"
RUNTIME_FILES = ("cholesky", "kkt", "call", "split_columns", "contact_call", "task_space",
                 "task_call", "fma_clones", "lanes_math", "lanes")
#: The line of a runtime file below which its text goes into the generated module (above it:
#: the file's own comment and the #includes that let it compile alone).
RUNTIME_MARKER = "/* eomgen: the generated module holds the text below this line. */\n"


@lru_cache(maxsize=None)
def runtime_source(name: str) -> str:
    """The text of runtime file ``templates/fast/runtime/<name>.c`` that a generated module
    includes: what follows its marker line, without the final newline."""
    text = (RUNTIME_DIR / f"{name}.c").read_text(encoding="utf-8")
    head, marker, body = text.partition(RUNTIME_MARKER)
    if not marker:
        raise ValueError(f"{RUNTIME_DIR / name}.c lacks the line {RUNTIME_MARKER.strip()}")
    return body.rstrip("\n")


#: parenthesize(x, _BARE) leaves only atoms (symbols, numbers) without parentheses
_BARE = PRECEDENCE["Atom"] - 1


class FastCPrinter(FloatLiteralMixin, C99CodePrinter):
    """C99 over doubles: the literals of :class:`~eomgen.symbolic.printing.FloatLiteralMixin`
    written as C doubles, ``x*x`` for small powers, ``1.0/sqrt(x)`` for ``x**(-1/2)`` (the
    powers a lanes kernel computes, :data:`LANES_EXPONENTS`, never ``pow``)."""

    def _literal(self, value: float) -> str:
        text = repr(value)
        return text if any(c in text for c in ".en") else text + ".0"

    def _print_Integer(self, expr):
        return f"{int(expr)}.0"

    def _print_Pow(self, expr):
        base, exponent = expr.args
        if exponent.is_Integer and 2 <= abs(int(exponent)) <= 4:
            factor = self.parenthesize(base, _BARE)
            product = "*".join([factor] * abs(int(exponent)))
            return product if exponent > 0 else f"1.0/({product})"
        if exponent == -1:
            return f"1.0/{self.parenthesize(base, _BARE)}"
        if exponent == sp.Rational(-1, 2):  # sqrt, not pow: a lanes kernel has no pow
            return f"1.0/sqrt({self._print(base)})"
        return super()._print_Pow(expr)


def c_string_literal(text: str) -> str:
    """A C string literal holding ``text`` in UTF-8; every byte outside printable ASCII, and
    ``"``, ``\\`` and ``?`` (trigraphs), as a three-digit octal escape."""
    out = []
    for byte in str(text).encode("utf-8"):
        char = chr(byte)
        out.append(char if 32 <= byte < 127 and char not in '"\\?' else f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def c_comment(text: str) -> str:
    """``text`` safe inside a C block comment (no ``*/``, ASCII only)."""
    return str(text).replace("*/", "* /").encode("ascii", "backslashreplace").decode("ascii")


#: Kernels of at least this many operations are compiled in two versions, with and without
#: fused multiply-add instructions, the loader picking the one the CPU runs (``target_clones``,
#: x86-64 Linux): for such kernels the arithmetic, not the Python call, is the time, and FMA
#: cuts it by about a third (the Panda's derivatives: 1.34 -> 0.97 µs per state in a batch);
#: smaller kernels keep one version (cloning doubles their compile time for little); the lanes
#: versions of batches are cloned whatever their size (:data:`LANES_OPERATIONS`).
#:
#: The rule, a clone only where it pays, measured kernel by kernel (issue 42,
#: benchmarks/fma_clones.py: the Panda's module built with the clones and with one plain
#: version, calls timed alternately, load 7–9 on 2 cores): clones / plain 0.75 for ∂τ (5,147
#: operations) and 0.85 for ∂q̈ (7,957) per one-state call (1,719 / 2,296 ns and 3,504 / 4,073
#: ns, the Python call included), 0.53 and 0.50 per state in a batch of 64: every clone above
#: this threshold pays. Below it, the ABA (1,747 operations) measured 0.76 one state and batch
#: alike (895 / 1,194 ns): a lower threshold would pay at run time too, for twice the compile
#: time of those kernels (the clones build of that module 140 s against 67 s plain) and new
#: golden files; it is left at 4000 until measured on more kernels between.
FMA_CLONE_OPERATIONS = 4000

#: Kernels of at least this many operations whose arithmetic a lanes kernel has
#: (:func:`in_lanes`) get one for batches: four states per SIMD vector, always compiled with and
#: without FMA (the FMA version is the AVX2 one), sin and cos by the runtime's vector routine
#: (runtime ``lanes_math.c``). Below this, a batch's time is mostly the loop and the
#: transposes, and the lanes version's compile time buys little.
LANES_OPERATIONS = 500

#: Kernels of more than this many operations get no lanes version: their batches go through the
#: one-state kernel, state by state (issues 42 and 43). GCC's time on a lanes kernel grows
#: faster than the kernel (about as its size squared above ten thousand operations), while what
#: the lanes buy per state stays about half the one-state kernel's time.
#:
#: Measured (benchmarks/README.md, "The lanes bound"): GCC's CPU time on each kernel's lanes
#: version (FMA-cloned, -O2) against what it buys per state in a batch of 1,000 on one thread
#: (lanes / the one-state kernel looped in C), on a 2-core machine at load 4–7. The Panda's
#: (fingers locked) τ, 598 operations: 0.8 s for 0.55; M, 613: 0.7 s for 0.55; ABA, 1,747: 1.9 s
#: for 0.31; ∂τ, 5,147: 10.5 s for 0.41; ∂q̈, 7,957: 18.8 s for 0.39 (at most 2.4 s per
#: thousand operations, paid back after 5–17 million states). solo12's C (free flyer), 10,022:
#: 56 s (5.6 s per thousand) for 0.48 (1.5 against 3.0 µs: 36 million states). Talos's C (free
#: flyer, 38 DOF), 32,017: about 500 s (16 s per thousand; its one-state version 121 s) for 0.68
#: (6.3 against 9.4 µs: 160 million states), nearly all of Talos's build. The bound lies
#: between the largest kernel measured to pay (the Panda's ∂q̈) and solo12's C. Without its FMA
#: clone a lanes version compiles hardly faster (solo12's C 54 s, ∂τ 10.6 s), so the bound is
#: on the lanes version itself.
LANES_MAX_OPERATIONS = 9000


def has_lanes(spec) -> bool:
    """Whether ``spec``'s function gets a lanes kernel: between :data:`LANES_OPERATIONS` and
    :data:`LANES_MAX_OPERATIONS` operations, and its arithmetic one a lanes kernel has
    (:func:`in_lanes`)."""
    return LANES_OPERATIONS <= spec.operation_count <= LANES_MAX_OPERATIONS and in_lanes(spec)


@dataclass(frozen=True)
class FastConfig:
    """Options of the fast backend."""

    template: str = "fast/module.c.jinja"
    suffix: str = "_fast"
    flags: tuple[str, ...] = ("-O2", "-fPIC", "-shared", "-fno-math-errno")


#: What a lanes kernel (a batch, several states per SIMD vector: runtime ``call.c``'s in_lanes)
#: computes: sums, products, these functions, and the powers the printer writes as products,
#: quotients and ``sqrt`` (the C vector extension has no other function nor any comparison).
LANES_FUNCTIONS = (sp.sin, sp.cos)
LANES_EXPONENTS = frozenset(sp.Rational(k) for k in (-4, -3, -2, -1, 2, 3, 4)) | {
    sp.Rational(1, 2), sp.Rational(-1, 2)}


def _lanes_ready(expr: sp.Expr) -> bool:
    for node in sp.preorder_traversal(expr):
        if node.is_Atom or node.is_Add or node.is_Mul:
            continue
        if node.is_Pow and node.exp in LANES_EXPONENTS:
            continue
        if isinstance(node, LANES_FUNCTIONS):
            continue
        return False
    return True


def in_lanes(spec) -> bool:
    """Whether the batch of ``spec``'s function may go through a lanes kernel: its whole
    program (assignments and output entries) in :data:`LANES_FUNCTIONS` and
    :data:`LANES_EXPONENTS`."""
    return (all(_lanes_ready(e) for _, e in spec.program.assignments)
            and all(_lanes_ready(e) for e in spec.output if e != 0))


def broadcast(spec, local: dict) -> frozenset:
    """The C locals (``t_…``) and output indices of ``spec``'s kernel whose value is a number:
    a lanes kernel broadcasts them to every lane."""
    rows, cols = spec.output.shape
    return frozenset([local[s].name for s, e in spec.program.assignments if e.is_Number]
                     + [r * cols + c for r in range(rows) for c in range(cols)
                        if spec.output[r, c].is_Number and spec.output[r, c] != 0])


def _render_source(job: Job, config: FastConfig, **extra) -> str:
    n = job.model.dof
    names: dict[sp.Symbol, sp.Symbol] = {}
    for k, parameter in enumerate(job.parameters):
        names[parameter.symbol] = sp.Symbol(f"p[{k}]", real=True)
    printer = FastCPrinter()
    # at least q, qd, tau of the composed forward dynamics
    max_inputs = max([3] + [len(spec.arguments) for spec in job.specs])
    max_length = max([job.model.nq, n] + [len(a.symbols) for spec in job.specs
                                           for a in spec.arguments])
    functions = []
    # one printer per layout of the vector inputs (the locals and parameters are named alike
    # in every function): the intermediates the functions share are printed once
    printers: dict[tuple, Callable[[sp.Expr], str]] = {}
    # intermediates become C locals named t_<name> (never a C keyword nor q, p, out)
    local = {symbol: sp.Symbol("t_" + symbol.name, real=True)
             for spec in job.specs for symbol, _ in spec.program.assignments}
    for spec in job.specs:
        # the j-th vector input is the kernel's pointer x[j], bound to a local of its name
        vectors = {symbol: sp.Symbol(f"{argument.name}[{k}]", real=True)
                   for argument in spec.arguments for k, symbol in enumerate(argument.symbols)}
        rename = {**names, **vectors, **local}

        def text(expr: sp.Expr, rename=rename) -> str:
            return printer.doprint(renamed(expr, rename))

        layout = tuple((a.name, tuple(a.symbols)) for a in spec.arguments)
        doprint = printers.setdefault(layout, printed_once(text))

        rows, cols = spec.output.shape
        lanes = has_lanes(spec)
        entries = [(r * cols + c, doprint(spec.output[r, c]))
                   for r in range(rows) for c in range(cols) if spec.output[r, c] != 0]
        functions.append(dict(
            name=spec.name, summary=spec.summary, inputs=[a.name for a in spec.arguments],
            one_signature=kernel_signature(spec.name),
            lanes_signature=kernel_signature(spec.name, lanes=True),
            slots=[f'"{a.name}"' for a in spec.arguments]
            + ["NULL"] * (max_inputs - len(spec.arguments)),
            # lengths of the inputs (NV for the joint vectors; F_c has the contact rows)
            sizes=["NQ" if a.name == "q" else str(len(a.symbols)) if a.name in INPUT_SIZES
                   else "NV" for a in spec.arguments]
            + ["0"] * (max_inputs - len(spec.arguments)),
            rows=rows, cols=0 if spec.is_vector else cols, size=rows * cols,
            assignments=[(local[s].name, doprint(e)) for s, e in spec.program.assignments],
            entries=entries, operation_count=spec.operation_count, units=spec.units,
            fma_clone=spec.operation_count >= FMA_CLONE_OPERATIONS,
            lanes=lanes, broadcast=broadcast(spec, local) if lanes else frozenset(),
            returns=spec.returns))
    # the docstrings open with a text signature (inspect.signature reads it)
    signature = "".join(", " + p.keyword
                        + ("" if p.default is None else f"={float(p.default)!r}")
                        for p in job.parameters)
    for f in functions:
        shape = f"({f['rows']}, {f['cols']})" if f["cols"] else f"({f['rows']},)"
        if f["returns"]:  # a tuple of results, each (rows, its columns) or (rows,)
            shape = "(" + ", ".join(f"{symbol} ({f['rows']}, {stop - start})" if stop is not None
                                    else f"{symbol} ({f['rows']},)"
                                    for symbol, start, stop in f["returns"]) + ")"
        keywords = ", *" + signature if signature else ""
        f["doc"] = c_string_literal(
            f"{f['name']}({', '.join(f['inputs'])}{keywords})\n--\n\n"
            f"{f['summary']}\n\nInputs of shape (NV,) or (N, NV) in JOINT_NAMES order"
            + "".join(f", {name} of shape ({size},) or (N, {size})" for name, size
                      in zip(f["inputs"], f["sizes"]) if size != "NV")
            + ("; returns the tuple " if f["returns"] else "; returns shape ")
            + f"{shape} or (N,) + that, in {f['units']}. {f['operation_count']} arithmetic "
            "operations per state.")
    forward_doc = c_string_literal(
        f"{FORWARD.function}({', '.join(FORWARD.inputs)}, *{signature}, "
        f"return_condition=False)\n--\n\n{FORWARD.summary}\n\n"
        "Warns IllConditionedWarning when (max L_ii / min L_ii)^2, a lower bound of cond(M), "
        "exceeds 1e-6 / eps; return_condition=True also returns that estimate. Raises "
        "numpy.linalg.LinAlgError when M is not positive definite and FloatingPointError when "
        "M, C qd + g or tau is not finite.")
    cfd = constrained_names()
    constrained = CONSTRAINED_FORWARD.function in exported(job.functions, "fast")
    # the contact rows m: the contact Jacobian's (its spec is generated whenever the composed
    # function is, CONSTRAINED_FORWARD.composed_from)
    nc = next((f["rows"] for f in functions if f["name"] == cfd["jacobian"]), 0)
    constrained_doc = c_string_literal(
        f"{cfd['name']}({', '.join(CONSTRAINED_FORWARD.inputs)}, *{signature}, damping=0.0)"
        f"\n--\n\n{CONSTRAINED_FORWARD.summary}\n\nReturns (qdd, F_c) of shapes (NV,), "
        f"({nc},) for one state, (N, NV), (N, {nc}) for a batch; F_c in CONTACT_ROWS order "
        "(forces on the robot). Solved by Cholesky factors: M = L L^T, A = J_c M^-1 J_c^T + "
        "damping 1 = L_A L_A^T, F_c = A^-1 (-J_c-dot qd - J_c M^-1 (tau - C qd - g)), qdd = "
        "M^-1 (tau - C qd - g + J_c^T F_c). Raises numpy.linalg.LinAlgError when M is not "
        "positive definite, or at damping 0 when A is numerically singular (a Cholesky pivot "
        "<= 1e-10 of A's largest diagonal entry: dependent contact rows, use damping > 0); "
        "FloatingPointError when M, C qd + g, tau, J_c or J_c-dot qd is not finite; "
        "ValueError for a damping not finite or < 0.")
    # issue 25: its derivatives (templates/fast/constrained_derivatives.c.jinja)
    derivatives = CONSTRAINED_DERIVATIVES.function in exported(job.functions, "fast")
    derivatives_doc = c_string_literal(
        f"{CONSTRAINED_DERIVATIVES.function}({', '.join(CONSTRAINED_DERIVATIVES.inputs)}, "
        f"*{signature}, damping=0.0)\n--\n\n{CONSTRAINED_DERIVATIVES.summary}\n\nReturns "
        f"(dqdd_dq, dqdd_dqd, dqdd_dtau) of shape (NV, NV) and (dF_dq, dF_dqd, dF_dtau) of "
        f"shape ({nc}, NV) (a leading N for a batch): {cfd['name']}'s solve, then its Cholesky "
        "factors on -constrained_dynamics_partials and [1; 0]; its errors.")
    task = _task_space_context(job, functions, signature)
    pid = parallel_names()
    parallel = PARALLEL_INVERSE.function in exported(job.functions, "fast")
    nl = next((f["rows"] for f in functions if f["name"] == pid["jacobian"]), 0)
    parallel_doc = c_string_literal(
        f"{pid['name']}({', '.join(PARALLEL_INVERSE.inputs)}, *{signature}, damping=0.0)"
        f"\n--\n\n{PARALLEL_INVERSE.summary}\n\nReturns (tau, lambda) of shapes (NV,), "
        f"({nl},) for one state, (N, NV), (N, {nl}) for a batch. With t = inverse dynamics and "
        "J_p, J_a the passive and actuated columns of J_l: (J_p J_p^T + damping 1) lambda = "
        "J_p t_p (Cholesky; least squares, exact for a square invertible J_p), tau_a = t_a - "
        "J_a^T lambda. Raises numpy.linalg.LinAlgError at damping 0 when J_p J_p^T is "
        "numerically singular (a singularity of the parallel robot), FloatingPointError when t "
        "or J_l is not finite.")
    parameters = [dict(name=c_string_literal(p.keyword),
                       default=("NAN" if p.default is None
                                else printer.doprint(sp.Float(p.default))),
                       has_default=int(p.default is not None),
                       doc=c_comment(p.doc))
                  for p in job.parameters]
    module = job.stem + config.suffix
    return render(
        config.template,
        header=[c_comment(line) for line in job.header_lines(config.template)],
        robot=c_comment(job.model.name),
        module=module,
        module_literal=c_string_literal(module),
        nq=job.model.nq,
        nv=n,
        max_inputs=max_inputs,
        max_length=max_length,
        joint_names=[c_string_literal(name) for name in job.dynamics.joint_names],
        configuration_names=[c_string_literal(name) for name in job.model.configuration_names],
        parameters=parameters,
        renamed=[(c_string_literal(p.name), c_string_literal(p.keyword))
                 for p in job.parameters if p.renamed],
        functions=functions,
        fma_clones=any(f["fma_clone"] or f["lanes"] for f in functions),
        constants=[(name, [c_string_literal(v) for v in values])
                   for name, values in job.constants],
        exports=[name for name, _ in job.constants] + list(exported(job.functions, "fast"))
        + warning_exports(job),
        forward_doc=forward_doc,
        forward_dynamics=FORWARD.function in job.functions,
        fd=composition_names(FORWARD),
        fd_operations=_forward_operations(functions, n),
        constrained_forward_dynamics=constrained,
        cfd=cfd,
        nc=nc,
        constrained_doc=constrained_doc,
        constrained_derivatives=derivatives,
        cfdd={"name": CONSTRAINED_DERIVATIVES.function, "partials": CONSTRAINED_PARTIALS.function},
        constrained_derivatives_doc=derivatives_doc,
        parallel_inverse=parallel,
        pid=pid,
        nl=nl,
        parallel_doc=parallel_doc,
        **parallel_indices(job.model),
        runtime={name: runtime_source(name) for name in RUNTIME_FILES},
        **task,
        **extra,
    )


def _forward_operations(functions: list[dict], n: int) -> int:
    """Operations per state of the composed forward dynamics (M, its bias, a Cholesky solve of
    about n³/3 + 2n²): what the batch's threads are counted by (runtime ``call.c``)."""
    names = composition_names(FORWARD)
    return (sum(f["operation_count"] for f in functions if f["name"] in
                (names["mass"], names["bias"])) + n ** 3 // 3 + 2 * n * n)


def render_source(job: Job, config, **extra) -> str:
    """``config.template`` rendered with the fast module's context (and ``extra``): what the
    C kernels backend (:mod:`.kernels_backend`) prints its files with, so that its kernels are the
    fast module's."""
    return _render_source(job, config, **extra)


#: The kind of result of each task-space function (TASK_INERTIA ... in runtime/task_call.c).
_TASK_KINDS = ("TASK_INERTIA", "TASK_BIAS", "TASK_INVERSE")


def _task_space_context(job: Job, functions: list[dict], signature: str) -> dict:
    """What the template needs to compose the task-space functions the module exports: the
    frames (``task_frames``, C literals), the names of the functions composed from
    (``ts``), each exported one's name, kind, inputs and docstring (``task_functions``), and
    whether the bias (which needs tau and J-dot qd) is among them (``task_bias``)."""
    wanted = [(o, kind) for o, kind in zip(TASK_SPACE, _TASK_KINDS)
              if o.function in exported(job.functions, "fast")]
    names = task_space_names()
    rows = next((f["rows"] for f in functions if f["name"] == names["jacobian"]), 0)
    frames = dict(job.constants).get("FRAME_NAMES", ())
    task_functions = []
    for output, kind in wanted:
        keywords = ", *" + signature + ", damping=0.0, linear=False, frames=None"
        task_functions.append(dict(
            name=output.function, kind=kind, inputs=output.inputs,
            doc=c_string_literal(
                f"{output.function}({', '.join(output.inputs)}{keywords})\n--\n\n"
                f"{output.summary}\n\nAs the NumPy module's (docs/legged.md): frames None "
                "(all of FRAME_NAMES), a name or index (no frame axis) or a sequence of them; "
                "linear=True keeps the 3 linear rows of J; (N,) in front for a batch. Raises "
                "numpy.linalg.LinAlgError when M is not positive definite or, at damping 0, "
                "when J M^-1 J^T of a frame is singular (a Cholesky pivot <= 1e-10 of its "
                "largest diagonal entry; use damping > 0)")))
    return dict(task_space=bool(wanted), task_functions=task_functions,
                task_bias=any(kind == "TASK_BIAS" for _, kind in wanted), ts=names,
                task_frames=[c_string_literal(name) for name in frames],
                task_nf=rows // 6)


def python_headers() -> tuple[str, ...] | None:
    """Include folders for Python's and NumPy's C headers, or None when ``Python.h`` is
    missing (a Python built without its development files)."""
    import numpy  # start-up time: only building the extension needs NumPy's headers

    include = sysconfig.get_paths().get("include")
    if not include or not Path(include, "Python.h").is_file():
        return None
    return include, numpy.get_include()


def compile_module(source: str, module: str, config: FastConfig = FastConfig(),
                   kernels: list[tuple[str, int]] = ()) -> bytes | str:
    """Compile the extension ``module`` from ``source``: the shared library's bytes, or a
    one-line reason why it was not built (no C compiler, no Python headers).

    With ``kernels`` (the module's kernels, ``(name, operations)``), the long ones are cut out
    into translation units (:func:`~.fast_units.split_source`) compiled in parallel
    (:func:`~eomgen.common.compiler.compile_jobs` at a time) and cached by content in the
    cache folder's ``objects`` (:class:`ObjectStore`), then linked into the one extension; its
    progress goes to :func:`eomgen.common.progress.current`."""
    compiler = c_compiler()
    if compiler is None:
        return "no C compiler found (set CC)"
    headers = python_headers()
    if headers is None:
        return "Python's C headers (Python.h) are not installed"
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    flags = [*config.flags, *(f"-I{h}" for h in headers)]
    units = split_source(source, module, list(kernels),
                         {name: runtime_source(name) for name in UNIT_RUNTIME}
                         ) if kernels else None
    if units is None:
        return shared_library(compiler, source, module, flags, suffix)
    return linked_library(compiler, [(u.name, u.text, u.weight) for u in units], module,
                          [f for f in flags if f != "-shared"],
                          [f for f in config.flags if f in ("-shared", "-fPIC")], suffix,
                          jobs=compile_jobs(), cache=ObjectStore(),
                          progress=progress_lines.current())


class ObjectStore:
    """Compiled objects of the fast module's translation units, kept in the derivation cache's
    folder (:func:`eomgen.cache.default_cache_dir`: ``generate``'s ``cache_dir`` when given,
    :func:`eomgen.cache.store.cache_folder`), in ``objects/``: entries signed as the
    derivation cache's are (:class:`eomgen.cache.store.Cache`; the least recently used beyond
    its limit deleted). A cache that cannot be read or written costs a compile, never the
    build."""

    def __init__(self, directory: Path | None = None):
        from ...cache.store import Cache, default_cache_dir  # only a split build needs it

        self._cache = Cache((directory or default_cache_dir()) / "objects")

    def get(self, key: str) -> bytes | None:
        try:
            entry = self._cache.get(key)
        except Exception:  # noqa: BLE001 - a broken cache must not fail the build
            return None
        if entry is None or len(entry.files) != 1 or not isinstance(entry.files[0].content, bytes):
            return None
        return entry.files[0].content

    def put(self, key: str, data: bytes) -> None:
        try:
            self._cache.put(key, [GeneratedFile("unit.o", data, golden=False)])
        except Exception:  # noqa: BLE001 - as in get
            pass


def load_fast(folder: Path, stem: str) -> Loaded:
    """The compiled fast module written into ``folder`` (imported under its own name, which
    its init function carries); functions take the input vectors positionally. A
    FileNotFoundError when it was not compiled (no C compiler)."""
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    path = folder / (stem + FastConfig.suffix + suffix)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: the fast module was not compiled (no C compiler?)")
    return positional(import_file(path, stem + FastConfig.suffix))


def emit_fast(job: Job, config: FastConfig = FastConfig()) -> list[GeneratedFile]:
    """The fast module's C source ``<stem>_fast.c`` (nothing compiled)."""
    module = job.stem + config.suffix
    return [GeneratedFile(module + ".c", _render_source(job, config))]


def build_fast(job: Job, emitted: list[GeneratedFile], config: FastConfig = FastConfig()
               ) -> list[GeneratedFile]:
    """The compiled extension module built from the emitted C source, or nothing (with a
    RuntimeWarning saying why) when no C compiler or no Python headers are found."""
    module = job.stem + config.suffix
    (source,) = [f.content for f in emitted if f.name == module + ".c"]
    built = compile_module(source, module, config,
                           [(spec.name, spec.operation_count) for spec in job.specs])
    if isinstance(built, bytes):
        suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
        return [GeneratedFile(module + suffix, built, golden=False)]
    warnings.warn(f"fast backend: {built}; wrote {module}.c only, not the compiled module",
                  RuntimeWarning, stacklevel=3)
    return []


@register("fast", "C extension module for Python (one state or a batch looped in C), "
          "compiled when a C compiler is found", config=FastConfig, order=40,
          printer=FastCPrinter, load=load_fast, emit=emit_fast, build=build_fast)
def generate_fast(job: Job, config: FastConfig = FastConfig()) -> list[GeneratedFile]:
    emitted = emit_fast(job, config)
    return emitted + build_fast(job, emitted, config)


__all__ = ["FastCPrinter", "FastConfig", "generate_fast", "render_source", "emit_fast", "build_fast",
           "compile_module", "c_string_literal", "python_headers"]
