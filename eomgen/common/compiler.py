"""The C compiler eomgen uses, looked up in one place: by the C backend (CasADi's C code and
its shared library), the fast backend (the CPython extension) and the derivation cache (whose
keys name the compiler, since it changes the files); and the one way the backends' build steps
run it (:func:`shared_library`)."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import tempfile
from pathlib import Path
from typing import Sequence

#: Tried in this order after ``$CC``.
CANDIDATES = ("cc", "gcc", "clang")


def c_compiler() -> str | None:
    """The C compiler to use: ``$CC``, else ``cc``, ``gcc`` or ``clang`` on ``PATH``, else None.

    Returns the name as given (``$CC`` or the candidate), which the backends run;
    :func:`c_compiler_path` resolves it."""
    for candidate in (os.environ.get("CC"), *CANDIDATES):
        if candidate and shutil.which(candidate):
            return candidate
    return None


def c_compiler_path() -> str | None:
    """The full path of :func:`c_compiler`, or None when there is none."""
    compiler = c_compiler()
    return shutil.which(compiler) if compiler else None


def shared_library(compiler: str, source: str, name: str, flags: Sequence[str],
                   suffix: str = ".so", message_limit: int = 800) -> bytes:
    """The bytes of the shared library ``<name><suffix>`` that ``compiler`` builds from the C
    ``source`` (written as ``<name>.c`` in a temporary folder): ``compiler *flags -o library
    <name>.c -lm``. ``flags`` say what to build (``-shared``, ``-fPIC``, include folders).

    Raises
    ------
    RuntimeError
        When the compiler fails: ``compiling <name>.c failed:`` and the first
        ``message_limit`` characters of what it printed.
    """
    with tempfile.TemporaryDirectory() as tmp:
        c_path = Path(tmp, name + ".c")
        c_path.write_text(source, encoding="utf-8")
        library = Path(tmp, name + suffix)
        returncode, stderr = run_compiler([compiler, *flags, "-o", str(library), str(c_path),
                                           "-lm"])
        if returncode != 0:
            raise RuntimeError(f"compiling {name}.c failed: {stderr.strip()[:message_limit]}")
        return library.read_bytes()


#: Seconds the compiler's process group has to end after SIGTERM before it gets SIGKILL.
STOP_GRACE = 2.0


def run_compiler(command: Sequence[str]) -> tuple[int, str]:
    """Run ``command`` (a compiler) and return its exit code and what it printed on stderr.

    The compiler runs in a process group of its own (``cc`` starts ``cc1``, ``as`` and ``ld``
    as children). Whatever ends the wait here (an interrupt, SIGTERM raised as an exception,
    any error), the whole group is sent SIGTERM, then SIGKILL after :data:`STOP_GRACE`
    seconds, and reaped before the exception goes on: no compiler outlives eomgen's call."""
    process = subprocess.Popen(list(command), stdin=subprocess.DEVNULL,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    try:
        _, stderr = process.communicate()
    except BaseException:
        stop_group(process)
        raise
    return process.returncode, stderr or ""


def stop_group(process: subprocess.Popen) -> None:
    """End ``process`` and every process of its group (SIGTERM, then SIGKILL), and reap it."""
    for signum, wait in ((signal.SIGTERM, STOP_GRACE), (signal.SIGKILL, None)):
        try:
            os.killpg(process.pid, signum)
        except (ProcessLookupError, PermissionError):
            pass
        try:
            process.communicate(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue
        except BaseException:  # a second interrupt while stopping: finish the job first
            continue


__all__ = ["c_compiler", "c_compiler_path", "run_compiler", "shared_library", "stop_group",
           "CANDIDATES", "STOP_GRACE"]
