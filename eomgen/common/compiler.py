"""The C compiler eomgen uses, looked up in one place: by the C backend (CasADi's C code and
its shared library), the fast backend (the CPython extension) and the derivation cache (whose
keys name the compiler, since it changes the files); and the one way the backends' build steps
run it (:func:`shared_library`, and for a source cut into translation units, :func:`linked_library`:
the units compiled in parallel, :func:`compile_jobs` of them at a time, each object cached by
content)."""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor
from concurrent.futures import wait as wait_for
from contextvars import ContextVar
from pathlib import Path
from typing import Callable, Iterator, Protocol, Sequence

from ..errors import GenerationError

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


#: The environment variable giving the compiler jobs of a build (``--jobs`` of ``eomgen generate``
#: overrides it; default: the machine's cores).
JOBS_VARIABLE = "EOMGEN_JOBS"

_jobs: ContextVar[int | None] = ContextVar("eomgen_compile_jobs", default=None)


@contextlib.contextmanager
def jobs_set(jobs: int | None) -> Iterator[None]:
    """Within the block, builds run ``jobs`` compilers at a time (None: :func:`compile_jobs`'s
    default); ``eomgen generate --jobs`` sets it around the generation."""
    if jobs is not None and (isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1):
        raise ValueError(f"jobs must be a whole number >= 1, not {jobs!r}")
    token = _jobs.set(jobs)
    try:
        yield
    finally:
        _jobs.reset(token)


def compile_jobs() -> int:
    """How many compilers a build runs at a time: what :func:`jobs_set` set, else
    ``$EOMGEN_JOBS``, else the number of cores this process may use. A GenerationError (exit 2
    from the command line) for an ``$EOMGEN_JOBS`` that is not a whole number >= 1."""
    jobs = _jobs.get()
    if jobs is not None:
        return jobs
    text = os.environ.get(JOBS_VARIABLE, "").strip()
    if text:
        try:
            value = int(text)
        except ValueError:
            value = 0
        if value < 1:
            raise GenerationError(f"{JOBS_VARIABLE}={text!r}: not a whole number >= 1")
        return value
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # not Linux
        return max(1, os.cpu_count() or 1)


class ObjectCache(Protocol):
    """Where :func:`linked_library` keeps compiled objects: ``get(key)`` the bytes stored under
    ``key`` (64 hex digits) or None, ``put(key, data)``; neither may raise."""

    def get(self, key: str) -> bytes | None: ...

    def put(self, key: str, data: bytes) -> None: ...


def object_key(compiler: str, flags: Sequence[str], text: str) -> str:
    """The cache key of the object ``compiler *flags -c`` makes of ``text``: SHA-256 of the
    compiler (its path, size and modification time, so that an upgrade changes it), the flags
    and the text."""
    path = shutil.which(compiler) or compiler
    try:
        info = os.stat(path)
        identity = f"{path}\0{info.st_size}\0{info.st_mtime_ns}"
    except OSError:
        identity = path
    digest = hashlib.sha256()
    for part in (identity, *flags, text):
        digest.update(part.encode("utf-8") + b"\0\1")
    return digest.hexdigest()


def linked_library(compiler: str, units: Sequence[tuple[str, str, int]], name: str,
                   flags: Sequence[str], link_flags: Sequence[str], suffix: str = ".so",
                   jobs: int = 1, cache: ObjectCache | None = None,
                   progress: Callable[[str], None] = lambda _: None,
                   message_limit: int = 800) -> bytes:
    """The bytes of the shared library ``<name><suffix>`` linked from translation units
    ``(stem, C text, weight)``: each compiled ``compiler *flags -c`` (at most ``jobs`` at a
    time, the heaviest first), its object taken from ``cache`` when an identical unit was
    compiled before (:func:`object_key`) and stored there when not, then all linked by
    ``compiler *link_flags -o library objects -lm``. ``progress`` gets a line as each unit is
    done (``compiling <name>: unit k of N (<stem>), 12 s``).

    Raises
    ------
    RuntimeError
        When a compiler fails: ``compiling <stem>.c failed:`` and the first ``message_limit``
        characters of what it printed (the other compilers are stopped first).
    """
    keys = [object_key(compiler, flags, text) for _, text, _ in units]
    objects: dict[int, bytes] = {}
    if cache is not None:
        for k, key in enumerate(keys):
            data = cache.get(key)
            if data is not None:
                objects[k] = data
    todo = sorted((k for k in range(len(units)) if k not in objects),
                  key=lambda k: -units[k][2])
    total, start = len(units), time.monotonic()
    running: set[subprocess.Popen] = set()
    lock = threading.Lock()
    with tempfile.TemporaryDirectory() as tmp:

        def compile_one(k: int) -> tuple[int, str]:
            stem, text, _ = units[k]
            c_path, o_path = Path(tmp, stem + ".c"), Path(tmp, stem + ".o")
            c_path.write_text(text, encoding="utf-8")
            mine: list[subprocess.Popen] = []

            def started(process: subprocess.Popen) -> None:
                with lock:
                    running.add(process)
                mine.append(process)

            try:
                return run_compiler([compiler, *flags, "-c", "-o", str(o_path), str(c_path)],
                                    started=started)
            finally:
                with lock:
                    running.difference_update(mine)

        done = total - len(todo)
        if done:
            progress(f"compiling {name}: {done} of {total} units from the cache")
        pool = ThreadPoolExecutor(max_workers=max(1, jobs), thread_name_prefix="eomgen-cc")
        try:
            pending = {pool.submit(compile_one, k): k for k in todo}
            while pending:
                finished, _ = wait_for(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    k = pending.pop(future)
                    returncode, stderr = future.result()
                    stem = units[k][0]
                    if returncode != 0:
                        raise RuntimeError(f"compiling {stem}.c failed: "
                                           f"{stderr.strip()[:message_limit]}")
                    objects[k] = Path(tmp, stem + ".o").read_bytes()
                    if cache is not None:
                        cache.put(keys[k], objects[k])
                    done += 1
                    progress(f"compiling {name}: unit {done} of {total} ({stem}), "
                             f"{time.monotonic() - start:.0f} s")
        except BaseException:
            for future in pending:
                future.cancel()
            with lock:  # their threads' waits then return, and the pool's shutdown reaps them
                for process in list(running):
                    try:
                        os.killpg(process.pid, signal.SIGKILL)
                    except (ProcessLookupError, PermissionError):
                        pass
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        paths = []
        for k, (stem, _, _) in enumerate(units):
            path = Path(tmp, stem + ".obj.o")
            path.write_bytes(objects[k])
            paths.append(str(path))
        library = Path(tmp, name + suffix)
        returncode, stderr = run_compiler([compiler, *link_flags, "-o", str(library), *paths,
                                           "-lm"])
        if returncode != 0:
            raise RuntimeError(f"linking {name}{suffix} failed: "
                               f"{stderr.strip()[:message_limit]}")
        return library.read_bytes()


#: Seconds the compiler's process group has to end after SIGTERM before it gets SIGKILL.
STOP_GRACE = 2.0


def run_compiler(command: Sequence[str],
                 started: Callable[[subprocess.Popen], None] | None = None) -> tuple[int, str]:
    """Run ``command`` (a compiler) and return its exit code and what it printed on stderr;
    ``started`` is called with the process once it runs (a caller that runs several at once
    keeps them, to stop them all when one fails).

    The compiler runs in a process group of its own (``cc`` starts ``cc1``, ``as`` and ``ld``
    as children). Whatever ends the wait here (an interrupt, SIGTERM raised as an exception,
    any error), the whole group is sent SIGTERM, then SIGKILL after :data:`STOP_GRACE`
    seconds, and reaped before the exception goes on: no compiler outlives eomgen's call."""
    process = subprocess.Popen(list(command), stdin=subprocess.DEVNULL,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
    if started is not None:
        started(process)
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
           "linked_library", "compile_jobs", "jobs_set", "object_key", "ObjectCache",
           "CANDIDATES", "STOP_GRACE", "JOBS_VARIABLE"]
