"""Faults of the machine while the output is written: one line naming the folder and the
cause, exit 2, and the folder's previous files intact (the files go to a staging folder first,
:func:`eomgen.common.output.write_atomically`).

A full disk is made with a file-size limit (``RLIMIT_FSIZE``, SIGXFSZ ignored, so that a write
past it fails with ``EFBIG`` as a full disk fails with ``ENOSPC``): the same path through the
code, and no privileges needed."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from support import run_process


#: Runs eomgen's CLI with a file-size limit of ``LIMIT`` bytes.
LIMITED = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
from eomgen.cli import main
main(sys.argv[2:], prog_name="eomgen")
"""


def _limited(limit: int, *args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", LIMITED, str(limit), *map(str, args)],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE as on Linux")
@pytest.mark.parametrize("fresh", [True, False], ids=["new folder", "existing folder"])
def test_a_write_that_fails_midway_leaves_the_folder_as_it_was(tmp_path, fresh):
    outdir = tmp_path / "out"
    before = {}
    if not fresh:
        outdir.mkdir()
        before = {"arm_numpy.py": b"# the previous generation\n", "notes.txt": b"mine\n"}
        for name, content in before.items():
            (outdir / name).write_bytes(content)
    # 4 kB: the NumPy module of the 3-link arm is larger, its first bytes fit
    result = _limited(4096, "generate", "elbow_rrr", "-o", outdir, "--backend", "numpy",
                      "--no-cache", "--name", "arm")
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert lines[-1].startswith(f"eomgen: error: {outdir}: cannot write the output: a file in "
                                ), result.stderr
    assert "Traceback" not in result.stderr
    if fresh:
        assert not outdir.exists()
    else:
        assert {p.name: p.read_bytes() for p in outdir.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ([] if fresh else ["out"])


def test_a_name_longer_than_the_file_system_allows(tmp_path):
    outdir = tmp_path / ("deep" * 70)  # 280 bytes
    result = run_process("generate", "planar_2link", "-o", outdir, "--backend", "numpy",
                         timeout=120)
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip().splitlines()[-1].endswith(
        "is 280 bytes, longer than the 255 bytes a name may have on this file system")
    assert list(tmp_path.iterdir()) == []


def test_a_long_name_that_fits_is_written(tmp_path):
    """250 bytes fit: the staging folder beside it must not borrow the name (it did, and
    passed 255 bytes)."""
    outdir = tmp_path / ("x" * 250)
    result = run_process("generate", "planar_2link", "-o", outdir, "--backend", "numpy",
                         "--no-cache", timeout=120)
    assert result.returncode == 0, result.stderr
    assert (outdir / "planar_2link_numpy.py").is_file()
    assert [p.name for p in tmp_path.iterdir()] == [outdir.name]
