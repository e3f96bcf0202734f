"""Generated files and how they are written: all of them or none.

Plain data and the standard library only (no SymPy): ``eomgen generate`` answers a request
from the derivation cache (:mod:`eomgen.cache`) with these two names alone.
"""

from __future__ import annotations

import os
import shutil
import signal
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence


@dataclass(frozen=True)
class GeneratedFile:
    """One output file. ``golden`` files are committed under ``generated/`` and compared by the
    golden test; build products (compiled libraries) are not."""

    name: str
    content: str | bytes
    golden: bool = True


def write_atomically(files: Sequence[GeneratedFile], outdir: Path) -> list[Path]:
    """Write ``files`` into ``outdir``: all of them or, on any failure, none.

    Files are first written into a staging folder beside ``outdir``; then they are moved in with
    ``os.replace`` while SIGINT and SIGTERM are held back, and the staging folder is removed.
    """
    outdir = Path(outdir)
    outdir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{outdir.name}.staging-", dir=outdir.parent))
    try:
        for f in files:
            target = staging / f.name
            if isinstance(f.content, bytes):
                target.write_bytes(f.content)
            else:
                target.write_text(f.content, encoding="utf-8", newline="\n")
        blocked = {signal.SIGINT, signal.SIGTERM}
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, blocked)
        try:
            outdir.mkdir(exist_ok=True)
            for f in files:
                os.replace(staging / f.name, outdir / f.name)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return [outdir / f.name for f in files]
