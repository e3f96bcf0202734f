"""What eomgen reads: regular files only. A named pipe, a device or a socket given as a
description, a scene or measurements would block a read forever (a pipe with no writer) or
never end (``/dev/zero``); :func:`not_regular` says what such a path is instead, in the words of
the one-line error."""

from __future__ import annotations

import os
import stat
from pathlib import Path

#: What a path that is not a regular file is, by the type bits of its mode.
_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a named pipe"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


def not_regular(path: Path | str) -> str | None:
    """None when ``path`` is a regular file (a symbolic link to one included); otherwise
    what is wrong, for an error message: ``"no such file"``, ``"cannot read it (…)"`` or
    ``"not a regular file: it is a named pipe"``. Nothing is opened."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "no such file"
    except OSError as exc:
        return f"cannot read it ({exc.strerror})"
    if stat.S_ISREG(mode):
        return None
    kind = next((name for test, name in _KINDS if test(mode)), "not a file")
    return f"not a regular file: it is {kind}"


__all__ = ["not_regular"]
