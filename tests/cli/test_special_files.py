"""Only regular files are read: a description, a scene or measurements that is a named pipe, a
device, a socket or a folder is refused in one line naming the path and what it is, exit 2,
nothing written, and nothing blocks (a pipe with no writer would block a read forever).

Run in real processes with a time limit, so that a blocking read fails the test instead of
hanging it."""

from __future__ import annotations

import os
import socket
from pathlib import Path

import pytest

import eomgen
from eomgen.errors import UnreadableFileError
from eomgen.scene import load_scene
from support import run_process

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes (POSIX)")


@pytest.fixture()
def specials(tmp_path):
    """A named pipe with a description's suffix, a symbolic link to a pipe, a socket, a
    dangling link."""
    pipe = tmp_path / "arm.urdf"
    os.mkfifo(pipe)
    linked = tmp_path / "scene.yaml"
    linked.symlink_to(pipe)
    server = socket.socket(socket.AF_UNIX)
    sock = tmp_path / "robot.yaml"
    server.bind(str(sock))
    dangling = tmp_path / "gone.yaml"
    dangling.symlink_to(tmp_path / "nowhere.yaml")
    yield {"pipe": pipe, "linked": linked, "socket": sock, "dangling": dangling}
    server.close()


def _refused(result, path: Path, what: str, out: Path) -> None:
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert lines[-1] == f"eomgen: error: {path}: {what}", result.stderr
    assert all("error" not in line for line in lines[:-1]), result.stderr  # progress lines only
    assert "Traceback" not in result.stderr and not out.exists()


def test_a_pipe_behind_a_link_as_the_scene(specials, tmp_path):
    out = tmp_path / "out"
    result = run_process("generate", "planar_2link", "--scene", specials["linked"], "-o", out,
                         "--backend", "numpy", timeout=60)
    _refused(result, specials["linked"], "not a regular file: it is a named pipe", out)


def test_a_socket_as_the_description(specials, tmp_path):
    out = tmp_path / "out"
    result = run_process("generate", specials["socket"], "-o", out, "--backend", "numpy",
                         timeout=60)
    _refused(result, specials["socket"], "not a regular file: it is a socket", out)


def test_a_device_as_the_scene(tmp_path):
    out = tmp_path / "out"
    result = run_process("generate", "planar_2link", "--scene", "/dev/null", "-o", out,
                         "--backend", "numpy", timeout=60)
    _refused(result, Path("/dev/null"), "not a regular file: it is a character device", out)


def test_a_pipe_as_the_measurements(specials, tmp_path):
    out = tmp_path / "out"
    result = run_process("identify", "planar_2link", specials["pipe"], "-o", out, timeout=120)
    _refused(result, specials["pipe"], "not a regular file: it is a named pipe", out)


def test_the_api_refuses_alike(specials):
    """``eomgen.load`` and ``load_scene`` as a user calls them: the same errors, no block."""
    with pytest.raises(UnreadableFileError, match="it is a named pipe"):
        eomgen.load(specials["pipe"])
    with pytest.raises(UnreadableFileError, match="it is a named pipe"):
        load_scene(specials["linked"])
    with pytest.raises(UnreadableFileError, match="no such file"):
        load_scene(specials["dangling"])
