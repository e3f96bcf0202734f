"""How every ``eomgen`` command ends: errors, interrupts and warnings on stderr.

:func:`handle_errors` wraps a command (and adds ``--debug``): an :class:`eomgen.errors.EomgenError`
is one line ``eomgen: error: ...`` and exit code 2; SIGINT and SIGTERM are the one line
``eomgen: interrupted`` and exit codes 130 and 143; a warning is one line
``eomgen: warning: ...``. With ``--debug``, errors and interrupts raise (a traceback).
"""

from __future__ import annotations

import contextlib
import functools
import signal
import sys
import threading
import warnings

import click

from ..errors import EomgenError, one_line, recorded_warnings  # noqa: F401  (the CLI's)
from ..common.progress import end_line, stop_heartbeats


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised wherever the program is (as SIGINT raises KeyboardInterrupt), so that
    the same cleanups run: a generation in progress leaves the previous output untouched."""


def _raise_terminated(signum, frame):
    raise Terminated()


@contextlib.contextmanager
def sigterm_raises():
    """Within the block, SIGTERM raises :class:`Terminated` (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def handle_errors(command):
    """Turn EomgenError into one line on stderr and exit code 2 (traceback with --debug), and
    an interrupt (SIGINT, SIGTERM) into ``eomgen: interrupted`` and exit code 130 or 143."""

    @functools.wraps(command)
    def wrapper(*args, debug: bool = False, **kwargs):
        def show_warning(message, category, filename, lineno, file=None, line=None):
            end_line()
            click.echo(f"eomgen: warning: {message}", err=True)

        warnings.showwarning = show_warning
        try:
            with sigterm_raises():
                try:
                    return command(*args, **kwargs)
                finally:
                    stop_heartbeats()  # no progress line once the command is over
        except EomgenError as exc:
            end_line()
            if debug:
                raise
            click.echo(f"eomgen: error: {exc}", err=True)
            sys.exit(2)
        except KeyboardInterrupt as exc:
            end_line()
            if debug:
                raise
            click.echo("eomgen: interrupted", err=True)
            sys.exit(128 + (signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT))

    return click.option("--debug", is_flag=True, help="Show a traceback on errors.")(wrapper)
