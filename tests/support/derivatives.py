"""Calling the generated derivative functions alike in every backend (tests/derivatives)."""

from __future__ import annotations

import numpy as np

from eomgen.outputs import OUTPUTS


def results(backend, module, function, *inputs, **parameters) -> tuple:
    """Every result of generated ``function`` as a tuple of float arrays: a several-result
    function's results (:attr:`eomgen.outputs.Output.returns`) or the one result; a CasADi
    function called by name with its named inputs, the others positionally (JAX and PyTorch
    arrays through NumPy)."""
    declared = OUTPUTS[function]
    if backend == "casadi":
        out = module[function].call({**dict(zip(declared.inputs, inputs)), **parameters})
        return tuple(np.array(out[s], dtype=float)
                     for s in (declared.returns or (declared.symbol,)))
    out = module[function](*inputs, **parameters)
    return tuple(np.asarray(x, dtype=float) for x in (out if declared.returns else (out,)))
