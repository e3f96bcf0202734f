"""The C compiler eomgen uses, looked up in one place: by the C backend (CasADi's C code and
its shared library), the fast backend (the CPython extension) and the derivation cache (whose
keys name the compiler, since it changes the files)."""

from __future__ import annotations

import os
import shutil

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


__all__ = ["c_compiler", "c_compiler_path", "CANDIDATES"]
