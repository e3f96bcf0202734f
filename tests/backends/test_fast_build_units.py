"""The fast module's split build (issue 42): its long kernels compiled as translation units of
their own, in parallel, each object cached by content, all linked into the one extension.

Checked against the single-unit build of the same emitted source (the results of every function
on a batch, and of the kernels with FMA clones and lanes versions), and by counting compiler
runs: a rebuild from a warm object cache compiles nothing and only links; a cache that cannot be
written costs no build. The emitted source itself is the golden file (tests/codegen).
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.codegen import make_job
from eomgen.codegen.backends import fast_backend, fast_units
from eomgen.codegen.backends.fast_backend import build_fast, emit_fast, python_headers
from eomgen.common import compiler
from eomgen.common.progress import reporting
from eomgen.dynamics import derive
from eomgen.errors import GenerationError
from support import load_module

pytestmark = pytest.mark.skipif(compiler.c_compiler() is None or python_headers() is None,
                                reason="needs a C compiler and Python's C headers")

FUNCTIONS = ("mass_matrix", "inverse_dynamics", "forward_dynamics",
             "inverse_dynamics_derivatives")


@pytest.fixture(scope="module")
def job():
    """The PUMA 560's first three joints with the derivatives of inverse dynamics."""
    model = eomgen.load(eomgen.example_path("puma560_arm3"))
    dynamics = derive(model, outputs=("M", "tau", "dtau"), simplify=False)
    return make_job(dynamics, FUNCTIONS)


def _build(job, folder, monkeypatch, unit_operations, clone_operations):
    """Emit and build the fast module with the given thresholds: (module, compiler runs,
    progress lines)."""
    monkeypatch.setattr(fast_units, "UNIT_OPERATIONS", unit_operations)
    monkeypatch.setattr(fast_backend, "FMA_CLONE_OPERATIONS", clone_operations)
    runs, lines = [], []
    real = compiler.run_compiler

    def counted(command, started=None):
        runs.append(list(command))
        return real(command, started)

    monkeypatch.setattr(compiler, "run_compiler", counted)
    emitted = emit_fast(job)
    with reporting(lines.append):
        built = build_fast(job, emitted)
    folder.mkdir()
    (binary,) = built
    (folder / binary.name).write_bytes(binary.content)
    return load_module(folder / binary.name, job.stem + "_fast"), runs, lines


def test_split_build_equals_one_unit_and_a_warm_cache_compiles_nothing(job, tmp_path,
                                                                       monkeypatch):
    monkeypatch.setenv("EOMGEN_CACHE_DIR", str(tmp_path / "cache"))
    counts = sorted(spec.operation_count for spec in job.specs)
    # the longest kernel alone in a unit of its own, with FMA clones and a lanes version
    longest = counts[-1]
    assert counts[-2] < longest
    split, runs, lines = _build(job, tmp_path / "split", monkeypatch, longest, longest)
    assert [r.count("-c") for r in runs] == [1, 1, 0]  # two units, then the link
    unit = [u for u in fast_units.split_source(
        emit_fast(job)[0].content, "m", [(s.name, s.operation_count) for s in job.specs],
        {name: fast_backend.runtime_source(name) for name in fast_units.UNIT_RUNTIME})
        if u.name != "m"]
    assert len(unit) == 1 and "FMA_CLONES void" in unit[0].text
    assert fast_units.kernel_signature(unit[0].name[3:], lanes=True) in unit[0].text
    assert lines[-1].startswith(f"compiling {job.stem}_fast: unit 2 of 2")
    single, single_runs, _ = _build(job, tmp_path / "single", monkeypatch, 10**9, longest)
    assert len(single_runs) == 1 and "-c" not in single_runs[0]
    rng = np.random.default_rng(3)
    n = job.model.dof
    for batch in (None, 9):  # one state, and a batch that goes through the lanes kernels
        shape = (n,) if batch is None else (batch, n)
        q, qd, qdd = (rng.uniform(-2, 2, shape) for _ in range(3))
        for name in FUNCTIONS:
            args = (q,) if name == "mass_matrix" else (q, qd, qdd)
            got, expected = getattr(split, name)(*args), getattr(single, name)(*args)
            for a, b in zip(got if isinstance(got, tuple) else (got,),
                            expected if isinstance(expected, tuple) else (expected,)):
                np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-13, err_msg=name)
    # the same units again: every object from the cache, only the link runs
    _, warm, lines = _build(job, tmp_path / "warm", monkeypatch, longest, longest)
    assert len(warm) == 1 and "-c" not in warm[0]
    assert lines == [f"compiling {job.stem}_fast: 2 of 2 units from the cache"]


def test_a_cache_that_cannot_be_written_costs_no_build(job, tmp_path, monkeypatch):
    blocked = tmp_path / "a_file"
    blocked.write_text("not a folder")
    monkeypatch.setenv("EOMGEN_CACHE_DIR", str(blocked))
    longest = max(spec.operation_count for spec in job.specs)
    module, runs, _ = _build(job, tmp_path / "built", monkeypatch, longest, 10**9)
    assert [r.count("-c") for r in runs] == [1, 1, 0]
    assert module.mass_matrix(np.zeros(job.model.dof)).shape == (job.model.dof,) * 2


def test_the_cut_finds_every_long_kernel_or_refuses(job):
    """Each unit past the first holds one kernel's definitions, non-static and hidden; the main
    unit declares them; a source whose kernel is not found is not split."""
    (source,) = [f.content for f in emit_fast(job)]
    kernels = [(s.name, s.operation_count) for s in job.specs]
    runtime = {name: fast_backend.runtime_source(name) for name in fast_units.UNIT_RUNTIME}
    units = fast_units.split_source(source, "m", [(name, 10**6) for name, _ in kernels], runtime)
    assert [u.name for u in units] == ["m"] + [f"m__{name}" for name, _ in kernels]
    for unit, (name, _) in zip(units[1:], kernels):
        signature = fast_units.kernel_signature(name)
        assert f"{fast_units.HIDDEN} {signature}\n{{\n" in unit.text
        assert f"{fast_units.HIDDEN} {signature};\n" in units[0].text
        assert f"static {signature}" not in units[0].text
    assert fast_units.split_source(source.replace("_one(", "_other("), "m",
                                   [(name, 10**6) for name, _ in kernels], runtime) is None
    assert fast_units.split_source(source, "m", [(name, 1) for name, _ in kernels], runtime) is None


def test_jobs_come_from_the_block_else_the_environment(monkeypatch):
    monkeypatch.setenv(compiler.JOBS_VARIABLE, "3")
    assert compiler.compile_jobs() == 3
    with compiler.jobs_set(1):
        assert compiler.compile_jobs() == 1
    monkeypatch.setenv(compiler.JOBS_VARIABLE, "zero")
    with pytest.raises(GenerationError, match="EOMGEN_JOBS='zero'"):
        compiler.compile_jobs()
    monkeypatch.delenv(compiler.JOBS_VARIABLE)
    assert compiler.compile_jobs() >= 1
    with pytest.raises(ValueError, match="jobs must be"):
        with compiler.jobs_set(0):
            pass


def test_generate_jobs_reaches_the_build_and_the_compile_is_reported(tmp_path, monkeypatch):
    """``eomgen generate --jobs 1``: the split build runs one compiler at a time and its
    progress lines name the units; ``--jobs 0`` is refused (exit 2) before any work."""
    from support import run_cli

    monkeypatch.setattr(fast_units, "UNIT_OPERATIONS", 1)
    seen = []
    real = compiler.linked_library

    def spy(*args, **kwargs):
        seen.append(kwargs["jobs"])
        return real(*args, **kwargs)

    monkeypatch.setattr(fast_backend, "linked_library", spy)
    result = run_cli("generate", eomgen.example_path("planar_2link"), "--backend", "fast",
                     "--no-cache", "--jobs", "1", "-o", tmp_path / "out")
    assert result.exit_code == 0, result.output
    assert seen == [1]
    assert "compiling planar_2link_fast: unit 1 of " in result.stderr
    refused = run_cli("generate", "--backend", "fast", "--jobs", "0", "-o", tmp_path / "no")
    assert refused.exit_code == 2 and "--jobs" in refused.stderr
    assert not (tmp_path / "no").exists()


def test_jobs_leave_the_command_cache_key_alone():
    from eomgen.cache import command_request

    arm = eomgen.example_path("planar_2link")
    keys = {command_request(arm, {"backends": "fast", "jobs": jobs}).key for jobs in (None, 1, 2)}
    assert len(keys) == 1


def test_the_objects_go_to_generates_cache_folder(tmp_path, monkeypatch):
    """``generate(..., cache_dir=D)`` (``--cache-dir``) keeps the compiled objects in D too,
    not in $EOMGEN_CACHE_DIR."""
    from eomgen.codegen.generate import generate

    monkeypatch.setenv("EOMGEN_CACHE_DIR", str(tmp_path / "environment"))
    monkeypatch.setattr(fast_units, "UNIT_OPERATIONS", 1)
    model = eomgen.load(eomgen.example_path("planar_2link"))
    generate(model, tmp_path / "out", ["fast"], functions=["M"], cache=False,
             cache_dir=tmp_path / "given")
    assert len(list((tmp_path / "given" / "objects" / "entries").glob("*.entry"))) == 2
    assert not (tmp_path / "environment").exists()
