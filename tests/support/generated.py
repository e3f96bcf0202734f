"""Generate a model's modules with every code backend, import them and call their functions
alike: the harness of the tests of the registered outputs (``tests/*/test_*_outputs.py``).

``call(function, *vectors, **parameters)`` runs a generated function and returns NumPy arrays;
CasADi functions are called by name (a parameter left out takes its default, as in the other
backends), the others positionally; each backend's registered ``load`` says how. JAX runs in
float64.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from eomgen.codegen import loadable_backends
from eomgen.codegen.functions import module_name, select_functions
from eomgen.codegen.generate import render_files

#: The code backends whose generated code can be loaded here (the optional ones when
#: installed), from the registry: a new backend is in every test that uses this harness.
BACKENDS = tuple(loadable_backends())


def generated(model, functions, folder: Path, backends=BACKENDS) -> tuple[dict, dict]:
    """``({backend: call}, {backend: module namespace})`` for ``model``'s modules exporting
    ``functions`` (names or symbols), written into ``folder``; each backend's registered
    ``load`` imports its code. ``call(function, *vectors, **parameters)`` gives NumPy arrays."""
    have = [b for b in backends if b in BACKENDS]
    stem = module_name(model.name)
    for f in render_files(model, have, functions=select_functions(functions)):
        path = folder / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    calls, modules = {}, {}
    for name in have:
        loaded = loadable_backends()[name].load(folder, stem)

        def call(function, *vectors, _call=loaded.call, **parameters):
            return np.asarray(_call(function, *vectors, **parameters), dtype=float)

        calls[name], modules[name] = call, dict(loaded.namespace)
    return calls, modules
