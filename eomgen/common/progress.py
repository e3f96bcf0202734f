"""Progress of long commands on stderr: stage lines in a log, one updating line on a terminal.

Every command that works for a while (``generate``, ``teach``, ``bench``, ``simulate``, ...)
reports through one :class:`Progress`, which the CLI makes from ``--quiet`` and hands down as a
plain callable ``progress(line)`` (library code never needs more, and defaults to a no-op):

* stderr is not a terminal (a log file, CI): each stage is one line
  ``eomgen: <stage> [+12.3 s]``, the time since the command started, so that a long run is
  never silent and its log says where the time went;
* stderr is a terminal: the stage replaces the previous one on a single line, cleared when the
  command ends;
* ``quiet``: nothing.

A command's :class:`Progress` is made with ``heartbeat=HEARTBEAT_SECONDS``: when a stage runs
longer than that (a derivation of a long chain, a C compile), its line is repeated with the
time spent in it, ``eomgen: <stage> (still working, 30 s) [+42.0 s]``, so that no stretch of
a command is silent for longer. The repeats come from a thread that
:func:`stop_heartbeats` ends (the CLI does, when a command returns or fails).

:meth:`Progress.steps` counts the steps of a loop (integrators, measurements): a click progress
bar on a terminal, and in a log a line at each tenth of the way and for each named step.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from contextvars import ContextVar
from typing import Callable, Iterator, TextIO

_current: ContextVar[Callable[[str], None] | None] = ContextVar("eomgen_progress", default=None)


@contextlib.contextmanager
def reporting(progress: Callable[[str], None]) -> Iterator[None]:
    """Within the block, :func:`current` is ``progress``."""
    token = _current.set(progress)
    try:
        yield
    finally:
        _current.reset(token)


def current() -> Callable[[str], None]:
    """The progress callable :func:`reporting` set, else one that prints nothing."""
    progress = _current.get()
    return progress if progress is not None else (lambda _: None)


#: The Progress whose terminal line is open (not ended by a newline), if any.
_open: "Progress | None" = None

#: Seconds a command's stage may run before its line is repeated (:class:`Progress`).
HEARTBEAT_SECONDS = 10.0

#: Progress objects whose heartbeat thread runs.
_beating: "set[Progress]" = set()


def stop_heartbeats() -> None:
    """End every heartbeat thread (:class:`Progress`); the CLI calls it when a command ends."""
    for progress in list(_beating):
        progress.stop()


def end_line() -> None:
    """End an open terminal progress line with a newline, keeping the stage on screen, so that
    a warning or an error printed next starts on a line of its own."""
    global _open
    if _open is not None and _open._pending:
        _open.stream.write("\n")
        _open.stream.flush()
        _open._pending = False
    _open = None


def plural(count: int, noun: str) -> str:
    """``"1 joint"``, ``"2 joints"``, ``"0 joints"``."""
    return f"{count} {noun}" + ("" if count == 1 else "s")


class Progress:
    """Stage lines on ``stream`` (default stderr); see the module docstring.

    Parameters
    ----------
    quiet:
        Print nothing.
    stream:
        Where to print (default: ``sys.stderr`` at the time of each call).
    tty:
        Whether ``stream`` is a terminal (default: ``stream.isatty()``).
    clock:
        Seconds, for the elapsed times (default: :func:`time.monotonic`).
    heartbeat:
        Repeat a stage's line when it has run this many seconds without a new one (module
        docstring); None: never.
    """

    def __init__(self, quiet: bool = False, stream: TextIO | None = None,
                 tty: bool | None = None, clock: Callable[[], float] = time.monotonic,
                 heartbeat: float | None = None):
        self.quiet = quiet
        self._stream = stream
        self._tty = tty
        self._clock = clock
        self._start = clock()
        self._pending = False  # a terminal line not yet cleared
        self._heartbeat = heartbeat
        self._lock = threading.Lock()
        self._stage: tuple[str, float] | None = None  # the last stage and when it began
        self._shown = 0.0  # when a line was last written
        self._stopped: threading.Event | None = None

    @property
    def stream(self) -> TextIO:
        return self._stream if self._stream is not None else sys.stderr

    @property
    def tty(self) -> bool:
        if self._tty is not None:
            return self._tty
        try:
            return self.stream.isatty()
        except (AttributeError, ValueError):
            return False

    def elapsed(self) -> float:
        """Seconds since the command started."""
        return self._clock() - self._start

    def __call__(self, line: str) -> None:
        """Report a stage (``line`` without the ``eomgen:`` prefix)."""
        if self.quiet:
            return
        with self._lock:
            self._stage = (line, self._clock())
            self._write(line)
        if self._heartbeat is not None and self._stopped is None:
            self._stopped = threading.Event()
            _beating.add(self)
            threading.Thread(target=self._beat, args=(self._stopped,), daemon=True,
                             name="eomgen-progress").start()

    def _write(self, line: str) -> None:
        if self.tty:
            global _open
            self.stream.write(f"\r\x1b[Keomgen: {line}")
            self._pending = True
            _open = self
        else:
            self.stream.write(f"eomgen: {line} [+{self.elapsed():.1f} s]\n")
        self.stream.flush()
        self._shown = self._clock()

    def _beat(self, stopped: threading.Event) -> None:
        """The heartbeat thread: repeat the stage's line when none was written for
        ``heartbeat`` seconds, until :meth:`stop`."""
        interval = self._heartbeat
        while not stopped.wait(min(interval / 4, 1.0)):
            with self._lock:
                now = self._clock()
                if stopped.is_set() or self._stage is None or now - self._shown < interval:
                    continue
                line, began = self._stage
                try:
                    self._write(f"{line} (still working, {now - began:.0f} s)")
                except (OSError, ValueError):  # the stream closed under us: nothing to say
                    return

    def stop(self) -> None:
        """End the heartbeat thread, if one runs (the next stage starts it again)."""
        stopped, self._stopped = self._stopped, None
        _beating.discard(self)
        if stopped is not None:
            stopped.set()

    def note(self, line: str) -> None:
        """A line that stays on a terminal too (e.g. a fallback taken), unless ``quiet``."""
        if self.quiet:
            return
        with self._lock:
            if self._pending:
                self.stream.write("\r\x1b[K")
                self._pending = False
            self.stream.write(f"eomgen: {line}\n")
            self.stream.flush()
            self._shown = self._clock()

    def clear(self) -> None:
        """End the updating terminal line (before printing results) and the heartbeat."""
        self.stop()
        if self._pending:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
            self._pending = False

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.clear()

    @contextlib.contextmanager
    def steps(self, total: int, label: str) -> Iterator["Steps"]:
        """Count ``total`` steps of ``label`` (see the module docstring); yields an object
        with ``update(n=1, name=None)``."""
        if self.quiet:
            yield Steps(self, total, label, None)
            return
        if self.tty:
            import click  # only for the terminal bar: library callers of Progress need no click

            self.clear()
            with click.progressbar(length=total, label=f"eomgen: {label}",
                                   file=self.stream) as bar:
                yield Steps(self, total, label, bar)
            return
        self(f"{label}: 0/{total}")
        yield Steps(self, total, label, None)


class Steps:
    """The counter :meth:`Progress.steps` yields."""

    def __init__(self, progress: Progress, total: int, label: str, bar):
        self._progress, self._total, self._label, self._bar = progress, max(total, 1), label, bar
        self._done = 0

    def update(self, n: int = 1, name: str | None = None) -> None:
        """``n`` more steps done; ``name`` (the step begun next, e.g. an integrator) is
        printed in a log."""
        before, self._done = self._done, self._done + n
        if self._progress.quiet:
            return
        if self._bar is not None:
            self._bar.update(n)
            return
        tenth = self._done * 10 // self._total > before * 10 // self._total
        if name is not None or tenth:
            self._progress(f"{self._label}: {self._done}/{self._total}"
                           + (f", {name}" if name else ""))
