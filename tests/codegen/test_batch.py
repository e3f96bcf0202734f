"""eomgen.analysis.batch.dask_map: generated functions over dask arrays, on a distributed.LocalCluster of
worker processes, equal to the NumPy module on the whole batch (the ``dask`` extra). Other
backends' functions through dask_map: with their own tests."""

from __future__ import annotations

import importlib
import sys

import numpy as np
import pytest

import eomgen
from eomgen.analysis.batch import dask_map
from eomgen.codegen.generate import generate
from support.extras import need

da = need("dask.array", reason="dask_map runs on dask")


@pytest.fixture(scope="module")
def planar(tmp_path_factory):
    """The planar arm's NumPy module, importable by name (workers import it by name too)."""
    outdir = tmp_path_factory.mktemp("planar")
    generate(eomgen.load(eomgen.example_path("planar_2link")), outdir, "numpy", cache=False)
    sys.path.insert(0, str(outdir))
    try:
        yield outdir, importlib.import_module("planar_2link_numpy")
    finally:
        sys.path.remove(str(outdir))
        sys.modules.pop("planar_2link_numpy", None)


def batch(count: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    return [rng.uniform(-np.pi, np.pi, (count, 2)) for _ in range(3)]


def test_dask_map_on_a_local_cluster_equals_the_numpy_batch(planar):
    distributed = need("distributed", reason="needs eomgen[dask] (distributed)")
    outdir, module = planar
    q, qd, qdd = batch(1001)
    masses = np.linspace(0.5, 1.5, len(q))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        client.upload_file(str(outdir / "planar_2link_numpy.py"))
        for function, args in ((module.mass_matrix, (q,)), (module.coriolis_matrix, (q, qd)),
                               (module.gravity_vector, (q,)),
                               (module.inverse_dynamics, (q, qd, qdd)),
                               (module.forward_dynamics, (q, qd, qdd))):
            lazy = dask_map(function, *args, chunks=300, m2=masses, g=3.7)
            assert lazy.chunks[0] == (300, 300, 300, 101)
            expected = function(*args, m2=masses, g=3.7)
            assert lazy.shape == expected.shape
            with distributed.get_task_stream(client) as stream:
                np.testing.assert_array_equal(lazy.compute(), expected)
            # the chunks ran on the cluster's worker processes
            workers = {task["worker"] for task in stream.data if task["key"][0] == lazy.name}
            assert len([t for t in stream.data if t["key"][0] == lazy.name]) == 4
            assert workers <= set(cluster.workers[k].worker_address for k in cluster.workers)


def test_dask_map_rejects_mismatched_inputs(planar):
    _, module = planar
    q, qd, _ = batch(10)
    with pytest.raises(ValueError, match=r"the same number of states N .*got \(10, 2\), \(9, 2\)"):
        dask_map(module.coriolis_matrix, q, qd[:9])
    with pytest.raises(ValueError, match="parameter m2 has 3 values for 10 states"):
        dask_map(module.gravity_vector, q, m2=np.ones(3))
    with pytest.raises(ValueError, match="at least one state"):
        dask_map(module.gravity_vector)


def test_a_statistic_is_reduced_chunk_by_chunk_block_by_block(planar):
    """With ``statistic``, each chunk gives one row (its statistic, computed ``block`` states at
    a time), and reducing the rows gives the statistic of the whole batch's results."""
    _, module = planar
    q, qd, qdd = batch(1001, seed=3)
    masses = np.linspace(0.5, 1.5, len(q))
    whole = module.inverse_dynamics(q, qd, qdd, m2=masses)  # (1001, 2)
    peak = dask_map(module.inverse_dynamics, q, qd, qdd, chunks=300, block=64, m2=masses,
                    statistic=lambda r: abs(r).max(axis=0))
    assert peak.shape == (4, 2) and peak.chunks[0] == (1, 1, 1, 1)
    rows = peak.compute(scheduler="synchronous")
    np.testing.assert_array_equal(rows[1], abs(whole[300:600]).max(axis=0))
    np.testing.assert_array_equal(rows.max(axis=0), abs(whole).max(axis=0))
    total = dask_map(module.mass_matrix, q, chunks=250, block=7,
                     statistic=lambda r: r.sum(axis=0)).sum(axis=0)
    np.testing.assert_allclose(total.compute(scheduler="synchronous"),
                               module.mass_matrix(q).sum(axis=0), rtol=1e-13)
    with pytest.raises(ValueError, match="block must be a positive number of states, got 0"):
        dask_map(module.gravity_vector, q, statistic=np.sum, block=0)


def draw(stream, block_id=None, block_info=None):
    """A chunk of 2-joint states from a generator seeded by (stream, chunk), made blockwise."""
    rng = np.random.default_rng([stream, block_id[0]])
    return rng.uniform(-np.pi, np.pi, (block_info[None]["chunk-shape"][0], 2))


def test_states_made_blockwise_are_fused_into_the_chunk_evaluation(planar):
    """dask fuses a chunk's evaluation with the blockwise tasks that make its states (here drawn
    chunk by chunk): one task per chunk (and a view of its result), so a cluster never stores or moves a chunk's states
    apart from its evaluation; the results are those of the whole batch."""
    import dask

    _, module = planar
    sizes = ((300, 300, 300, 101), (2,))
    q, qd = (da.map_blocks(draw, k, chunks=sizes, dtype=float, meta=np.empty((0, 2)))
             for k in range(2))
    whole = module.coriolis_matrix(q.compute(), qd.compute())
    lazy = dask_map(module.coriolis_matrix, q, qd)
    peak = dask_map(module.coriolis_matrix, q, qd, statistic=lambda r: abs(r).max(axis=0))
    for result in (lazy, peak):
        (optimized,) = dask.optimize(result)
        graph = optimized.__dask_graph__()
        assert not [key for key in graph if key[0].startswith("draw-")]  # drawn inside
        assert len(graph) == 2 * 4  # per chunk, the evaluation and a view of its result
    np.testing.assert_array_equal(lazy.compute(scheduler="synchronous"), whole)
    np.testing.assert_array_equal(peak.compute(scheduler="synchronous").max(axis=0),
                                  abs(whole).max(axis=0))


def test_configuration_and_velocity_of_different_sizes():
    """q of NQ columns beside velocities of NV ≠ NQ columns (a quaternion base): each keeps its
    width, split into chunks of states only."""
    q = np.arange(30.0).reshape(10, 3)
    v = np.arange(20.0).reshape(10, 2) / 7

    def function(q, v):
        return q[:, :2] * v + q[:, 2:]

    lazy = dask_map(function, da.from_array(q, chunks=(4, 1)), v, chunks=4)
    assert lazy.chunks == ((4, 4, 2), (2,))
    np.testing.assert_array_equal(lazy.compute(scheduler="synchronous"), function(q, v))
