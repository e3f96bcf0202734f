"""Generate a model's modules with every code backend, import them and call their functions
alike: the harness of the tests of the registered outputs (``tests/test_*_outputs.py``).

``call(function, *vectors, **parameters)`` runs a generated function and returns NumPy arrays;
CasADi functions are called by name (a parameter left out takes its default, as in the other
backends), the others positionally. JAX runs in float64.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from eomgen.codegen.backends.casadi_backend import load_module_source
from eomgen.codegen.functions import module_name, select_functions
from eomgen.codegen.generate import render_files
from eomgen.outputs import OUTPUTS

#: The code backends, the optional ones when installed.
BACKENDS = ("numpy", "casadi", "fast") + tuple(
    b for b in ("jax", "torch") if importlib.util.find_spec(b) is not None)


def generated(model, functions, folder: Path, backends=BACKENDS) -> tuple[dict, dict]:
    """``({backend: call}, {backend: module namespace})`` for ``model``'s modules exporting
    ``functions`` (names or symbols), written into ``folder``."""
    have = [b for b in backends if b in BACKENDS]
    if "jax" in have:
        import jax

        jax.config.update("jax_enable_x64", True)
    stem = module_name(model.name)
    files = {f.name: f for f in render_files(model, have, functions=select_functions(functions))}
    for f in files.values():
        path = folder / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    calls, modules = {}, {}
    for name in have:
        if name == "casadi":
            module = load_module_source(files[f"{stem}_casadi.py"].content,
                                        f"{stem}_ca_{folder.name}")

            def call(function, *vectors, _module=module, **parameters):
                declared = OUTPUTS[function]
                named = {**dict(zip(declared.inputs, vectors)), **parameters}
                result = _module[function].call(named)
                out = np.array(result[declared.symbol] if declared.symbol
                               else next(iter(result.values())), dtype=float)
                return out.ravel() if declared.is_vector else out
        else:
            path = (next(folder.glob(f"{stem}_fast.*.so")) if name == "fast"
                    else folder / f"{stem}_{name}.py")
            spec = importlib.util.spec_from_file_location(
                f"{stem}_fast" if name == "fast" else f"{stem}_{name}_{folder.name}", path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            module = vars(module)

            def call(function, *vectors, _module=module, **parameters):
                return np.asarray(_module[function](*vectors, **parameters), dtype=float)
        calls[name], modules[name] = call, module
    return calls, modules
