"""Batches larger than one machine's memory: any generated function over a ``dask.array``.

:func:`dask_map` turns a generated function (the inverse dynamics of a NumPy module, or a JAX
function, jitted or not) and state arrays of shape ``(N, NV)`` into a lazy ``dask.array`` of
its results, evaluated chunk by chunk of states by whatever dask scheduler is active: threads,
processes, or a ``distributed`` cluster. Needs the ``dask`` extra (``pip install
eomgen[dask]``); nothing here imports dask until it is called.

Workers of a ``distributed`` cluster in other processes import the generated module by name:
upload it first with ``client.upload_file("ur5_numpy.py")`` (or install it where they run).
See ``docs/backends.md``.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = ["dask_map"]

_AXES = "abcdefgh"  # names of the output's per-state axes in dask's blockwise notation
_JOINT_AXES = "zyxwvu"  # the state arrays' joint axes, one letter per width (NQ, NV, ...)


def dask_map(function: Callable, *states, chunks: int = 100_000,
             statistic: Callable | None = None, block: int = 4096, **parameters):
    """``function(*states, **parameters)`` over a batch of states, chunk by chunk, lazily; or,
    with ``statistic``, one statistic of the results per chunk, reduced where the chunk runs.

    Parameters
    ----------
    function : callable
        A generated function taking state arrays of shape ``(N, NQ)`` (q) or ``(N, NV)``
        (the others) and returning an array of
        shape ``(N,) + S`` (``S = (NV,)`` for vectors, ``(NV, NV)`` for matrices), e.g. the
        NumPy module's inverse dynamics (see :data:`eomgen.outputs.OUTPUTS`), or a JAX one (its
        results are copied back to NumPy).
    *states : array or dask.array, shape (N, NQ) for q, (N, NV) for the others
        The function's state arguments (q, qd, ...), in CONFIGURATION_NAMES and JOINT_NAMES
        order. NumPy arrays are
        split into chunks of ``chunks`` states; dask arrays are rechunked to the first one's
        chunks of states, with all joints of a state in one chunk. Dask arrays made blockwise
        (``dask.array.map_blocks`` of a function drawing or reading a chunk) are fused into
        their chunk's evaluation: one task per chunk, whose states are never stored apart.
    chunks : int
        States per chunk when the first state argument is not a dask array already.
    statistic : callable, optional
        A reduction over the first axis, ``statistic(r) -> R`` for results ``r`` of shape
        ``(n,) + S``, such as ``lambda r: abs(r).max(axis=0)`` or ``lambda r: r.sum(axis=0)``.
        It must give the same answer on the stacked statistics of parts as on the whole (max,
        min, sum, …; for a mean, sum and divide). Each chunk is then evaluated ``block`` states
        at a time and only its statistic leaves the worker: the results of a chunk are never
        held in memory at once (10⁷ states of a 7 × 7 derivative are 3.9 GB; their largest
        entries, 392 bytes a chunk). Reduce the chunks' statistics with the same reduction,
        e.g. ``dask_map(f, q, statistic=...).max(axis=0)``.
    block : int
        States per call of ``function`` inside a chunk when ``statistic`` is given: small
        enough for the results of a block to stay in the CPU's cache.
    **parameters : float or array of shape (N,)
        The module's parameter keywords; arrays of shape (N,) go chunk by chunk with their
        states. Parameters left out take the module's defaults (the description's values).

    Returns
    -------
    dask.array.Array, shape (N,) + S, float64; with ``statistic``, shape (chunks,) + R
        Lazy: call ``.compute()``, or store it chunk by chunk (``dask.array.to_zarr``, ...).

    Raises
    ------
    ValueError
        When no state is given, the states are not 2-D arrays of the same number of states,
        or ``block`` is not a positive integer.
    ImportError
        When dask is not installed.
    """
    try:  # optional dependency (eomgen[dask])
        import dask.array as da
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("eomgen.analysis.batch.dask_map needs dask: pip install 'eomgen[dask]'") from exc
    if not states:
        raise ValueError("dask_map: give at least one state array (q, ...)")
    if not isinstance(block, (int, np.integer)) or block < 1:
        raise ValueError(f"dask_map: block must be a positive number of states, got {block!r}")
    arrays = [x if isinstance(x, da.Array) else da.from_array(np.asarray(x, dtype=float),
                                                             chunks=(chunks, -1))
              for x in states]
    if any(x.ndim != 2 for x in arrays) or len({x.shape[0] for x in arrays}) != 1:
        raise ValueError("dask_map: the states must be 2-D arrays of the same number of "
                         "states N ((N, NQ) for q, (N, NV) for the others), got "
                         + ", ".join(str(x.shape) for x in arrays))
    rows = arrays[0].chunks[0]
    arrays = [x.rechunk((rows, -1)) for x in arrays]
    per_state = {name: value for name, value in parameters.items() if np.ndim(value) == 1}
    fixed = {name: value for name, value in parameters.items() if name not in per_state}
    for name, value in per_state.items():
        if len(value) != arrays[0].shape[0]:
            raise ValueError(f"dask_map: parameter {name} has {len(value)} values for "
                             f"{arrays[0].shape[0]} states")
    columns = [da.asarray(value).rechunk((rows,)) for value in per_state.values()]
    # The shape of one state's result, from the first state (a tiny computation).
    first = function(*(np.asarray(x[:1]) for x in arrays), **fixed,
                     **{name: np.asarray(c[:1]) for name, c in zip(per_state, columns)})
    shape = np.shape(first)[1:]
    names = list(per_state)

    def evaluate(*blocks):
        block_states, block_parameters = blocks[:len(arrays)], blocks[len(arrays):]
        return np.asarray(function(*block_states, **fixed,
                                   **dict(zip(names, block_parameters))), dtype=float)

    # Each state array's joint axis (one chunk) gets a letter of its own width and is KEPT in
    # the output, cut to length 1 and indexed away afterwards: a contracted index would stop
    # dask from fusing the chunk task with the tasks that make its states (a blockwise draw of
    # random states, a load), and each chunk's states would be separate tasks, stored and
    # possibly moved between workers before the evaluation.
    widths = list(dict.fromkeys(x.shape[1] for x in arrays))
    joint_axes = _JOINT_AXES[:len(widths)]
    pairs = [item for x in arrays for item in (x, "i" + joint_axes[widths.index(x.shape[1])])]
    pairs += [item for c in columns for item in (c, "i")]
    kept = {axis: 1 for axis in joint_axes}
    cut = (slice(None),) + (0,) * len(joint_axes)

    def lazy(chunk_function, result_shape, states_per_chunk):
        axes = _AXES[:len(result_shape)]

        def with_joint_axes(*blocks):
            result = chunk_function(*blocks)
            return result.reshape(result.shape[:1] + (1,) * len(joint_axes) + result.shape[1:])

        adjust = {"i": states_per_chunk, **kept} if states_per_chunk else kept
        result = da.blockwise(with_joint_axes, "i" + joint_axes + axes, *pairs, dtype=float,
                              new_axes=dict(zip(axes, result_shape)), adjust_chunks=adjust,
                              meta=np.empty((0,) * (1 + len(joint_axes) + len(result_shape))))
        return result[cut]

    if statistic is None:
        return lazy(evaluate, shape, None)

    def reduce_chunk(*chunk):
        parts = [np.asarray(statistic(evaluate(*(x[start:start + block] for x in chunk))))
                 for start in range(0, len(chunk[0]), block)]
        return np.asarray(statistic(np.stack(parts)), dtype=float)[np.newaxis]

    return lazy(reduce_chunk, np.shape(statistic(first)), 1)
