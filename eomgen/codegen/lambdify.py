"""NumPy functions of derived dynamics, in memory: :meth:`eomgen.Dynamics.lambdify`.

The functions are those of the generated NumPy module (``eomgen generate --backend numpy``):
the same straight-line program printed by the same backend's printer and template (terms in
SymPy's internal order rather than sorted, so results may differ from the file's in the last
bit), compiled into a module object that is never written to disk. Nothing is expanded, so this takes about as long as printing the
program (well under a second for a 7-joint arm), where ``sympy.lambdify`` of the expanded
matrices takes minutes.
"""

from __future__ import annotations

import types
from dataclasses import dataclass
from typing import Callable

from ..outputs import BY_SYMBOL, FORWARD, OUTPUTS
from ..symbolic.printing import exec_source


@dataclass(frozen=True)
class NumericDynamics:
    """NumPy callables for one model's derived dynamics.

    Each takes joint vectors of shape ``(n,)`` (one state) or ``(N, n)`` (a batch), in
    ``joint_names`` order [rad, m; rad/s, m/s; rad/s², m/s²], and the parameters kept symbolic
    as keyword arguments (``parameters`` lists the keywords; defaults are the description's
    values). An output that was not derived is None.

    Attributes
    ----------
    M:
        ``M(q, **parameters)``: mass matrix, ``(n, n)`` or ``(N, n, n)``.
    C:
        ``C(q, qd, **parameters)``: Coriolis matrix (Christoffel symbols of the first kind).
    g:
        ``g(q, **parameters)``: gravity vector, ``(n,)`` or ``(N, n)``.
    tau:
        ``tau(q, qd, qdd, **parameters)``: inverse dynamics ``M q̈ + C q̇ + g``.
    forward:
        ``forward(q, qd, tau, **parameters)``: joint accelerations (a Cholesky solve).
    parameters, symbols:
        The keyword of each parameter kept symbolic, and its SymPy symbol (same order).
    module:
        The compiled module, the same text as the generated ``<robot>_numpy.py``.
    source:
        That text.
    """

    joint_names: tuple[str, ...]
    parameters: tuple[str, ...]
    symbols: tuple
    M: Callable | None
    C: Callable | None
    g: Callable | None
    tau: Callable | None
    forward: Callable | None
    module: types.ModuleType
    source: str


def lambdify(dynamics: "eomgen.dynamics.Dynamics") -> NumericDynamics:  # noqa: F821
    """Compile the NumPy module of ``dynamics`` in memory (see :class:`NumericDynamics`).

    Examples
    --------
    >>> import numpy as np, eomgen
    >>> dyn = eomgen.derive(eomgen.load(eomgen.example_path("planar_2link")))
    >>> f = dyn.lambdify()
    >>> f.parameters[:3]  # sorted by name: the description's names
    ('I1', 'I2', 'g')
    >>> np.round(f.g(np.zeros(2), m2=2.0), 4)
    array([34.335,  9.81 ])
    >>> np.round(f.g(np.zeros(2), g=1.62), 4)  # on the Moon
    array([3.24, 0.81])
    """
    # Imported on first use (start-up time): code generation loads Jinja and the backends,
    # which `import eomgen` and derive never need.
    from .job import make_job
    from .backends.numpy_backend import NumPyConfig, NumPyModulePrinter, numpy_source

    derived = set(dynamics.outputs)
    functions = [f for f, o in OUTPUTS.items() if set(o.needs) <= derived]
    job = make_job(dynamics, functions, count_operations=False)
    # The NumPy backend's printer and template; terms in SymPy's internal order (sorting them
    # for a readable file is most of the printing time).
    printer = NumPyModulePrinter({"fully_qualified_modules": True, "standard": "python3",
                                  "order": "none"})
    config = NumPyConfig()
    content = numpy_source(job, printer, config)
    module = types.ModuleType(f"eomgen_lambdified_{job.stem}")
    module.__file__ = f"<eomgen lambdify {job.stem}>"
    exec_source(content, module.__file__, module.__dict__)

    def get(name):
        return getattr(module, name, None) if name in functions else None

    return NumericDynamics(
        dynamics.joint_names, tuple(p.keyword for p in job.parameters),
        tuple(p.symbol for p in job.parameters),
        get(BY_SYMBOL["M"].function), get(BY_SYMBOL["C"].function),
        get(BY_SYMBOL["g"].function), get(BY_SYMBOL["tau"].function), get(FORWARD.function),
        module, content)
