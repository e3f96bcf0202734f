"""Interrupting ``eomgen generate`` (SIGINT, SIGTERM) mid-derivation and mid-compile.

A 12-link spatial chain takes seconds to derive. ``eomgen generate`` runs on it in a real
process, over a folder holding a previous complete output; once the process reports that it is
deriving, it is sent SIGINT (Ctrl-C) or SIGTERM. It must say ``eomgen: interrupted`` (one line,
no traceback) and exit with 130 or 143, leave the previous output byte for byte, and leave no
staging folder or temporary file behind (in the output's parent folder nor in the cache).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from support.reference import random_robot, to_urdf

ROBOT = "random_chain_12"
PREVIOUS = {f"{ROBOT}_numpy.py": b"# the previous generation (numpy)\n",
            f"{ROBOT}_casadi.py": b"# the previous generation (casadi)\n",
            f"{ROBOT}.tex": b"% the previous generation\n",
            "notes.txt": b"not eomgen's\n"}


@pytest.fixture(scope="module")
def chain(tmp_path_factory) -> Path:
    model = random_robot(np.random.default_rng(5), 12)
    assert model.name == ROBOT and model.dof == 12
    path = tmp_path_factory.mktemp("chain") / "chain12.urdf"
    path.write_text(to_urdf(model), encoding="utf-8")
    return path


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir()}


#: Calls of the before-fork hooks in this process: Python code run between fork and exec,
#: as a ``preexec_fn`` does (JAX, loaded by other tests in the same process, warns then that
#: os.fork() may deadlock; plain subprocess starts call no hook).
FORK_HOOKS: list[int] = []
os.register_at_fork(before=lambda: FORK_HOOKS.append(1))


@contextmanager
def _children_with_default_sigint():
    """Children of a shell without job control inherit SIGINT ignored; Python then never
    raises KeyboardInterrupt. The test wants eomgen's own handling, so while the child starts,
    SIGINT is handled here: exec resets a handled signal to its default (an ignored one stays
    ignored). No ``preexec_fn``: it would run Python in the forked child of a multithreaded
    process."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["SIGINT", "SIGTERM"])
def test_interrupt_mid_derivation_keeps_the_previous_output(chain, tmp_path, signum, code):
    work = tmp_path / "work"
    outdir = work / "out"
    outdir.mkdir(parents=True)
    for name, content in PREVIOUS.items():
        (outdir / name).write_bytes(content)
    cache = tmp_path / "cache"
    hooks = len(FORK_HOOKS)
    with _children_with_default_sigint():
        process = subprocess.Popen(
            [sys.executable, "-m", "eomgen.cli", "generate", str(chain), "-o", str(outdir),
             "--backend", "numpy,casadi,latex", "--cache-dir", str(cache)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert len(FORK_HOOKS) == hooks  # issue 29: no Python ran between fork and exec
    try:
        seen = []
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            line = process.stderr.readline()
            if not line:
                break
            seen.append(line)
            if "deriving" in line:
                break
        assert seen and "deriving" in seen[-1], "".join(seen)
        time.sleep(0.5)  # well inside the derivation, which takes seconds
        assert process.poll() is None, "the derivation ended before the signal"
        process.send_signal(signum)
        stdout, rest = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    stderr = "".join(seen) + rest
    assert process.returncode == code, stderr
    assert stdout == ""
    assert "Traceback" not in stderr
    other = [line for line in stderr.splitlines() if not line.startswith("eomgen: deriving")]
    assert other == ["eomgen: interrupted"], stderr
    assert _snapshot(outdir) == PREVIOUS
    assert [p.name for p in work.iterdir()] == ["out"]  # no staging folder
    leftovers = [p for p in cache.rglob("*") if p.name.startswith(".")] if cache.exists() else []
    assert leftovers == []


def _children_of(pid: int) -> list[int]:
    """Processes whose parent is ``pid`` (from /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc to find the compiler")
@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["SIGINT", "SIGTERM"])
def test_interrupt_during_the_compile_ends_the_compiler(tmp_path, signum, code):
    """A signal to eomgen alone (not to its process group, as ``kill`` sends it) while the C
    compiler runs: eomgen ends the compiler and what the compiler started, then exits.

    The compiler is a stand-in (``$CC``, which eomgen honours): a script that starts a child,
    as ``cc`` starts ``cc1``, and waits for it; both must be gone when eomgen has exited."""
    compiler = tmp_path / "slow-cc"
    compiler.write_text("#!/bin/sh\nsleep 300 &\nwait\n", encoding="utf-8")
    compiler.chmod(0o755)
    outdir = tmp_path / "out"
    env = {**os.environ, "CC": str(compiler)}
    with _children_with_default_sigint():
        process = subprocess.Popen(
            [sys.executable, "-m", "eomgen.cli", "generate", "planar_2link", "-o", str(outdir),
             "--backend", "fast", "--no-cache"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        deadline, sleeper, cc = time.monotonic() + 120, None, None
        while time.monotonic() < deadline and sleeper is None and process.poll() is None:
            for child in _children_of(process.pid):
                grandchildren = _children_of(child)
                if grandchildren:
                    cc, sleeper = child, grandchildren[0]
            time.sleep(0.05)
        assert sleeper is not None, "the stand-in compiler never started"
        process.send_signal(signum)
        stdout, stderr = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == code, stderr
    assert stderr.strip().splitlines()[-1] == "eomgen: interrupted", stderr
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and (_alive(cc) or _alive(sleeper)):
        time.sleep(0.05)
    assert not _alive(cc) and not _alive(sleeper), "the compiler outlived eomgen"
    assert not outdir.exists()
