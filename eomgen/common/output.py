"""Generated files and how they are written: all of them or none, checked before the work.

Plain data and the standard library only (no SymPy): ``eomgen generate`` answers a request
from the derivation cache (:mod:`eomgen.cache`) with these names alone.

* :func:`check_output_folder` and :func:`check_output_file` tell, before any work, whether an
  output can be written where it is asked for (an existing file given as a folder, a parent
  that is a file, a read-only or virtual file system such as ``/proc``), as one-line
  :class:`OutputError` naming the path and the problem. They try for real (a probe folder made
  and removed at once), since permission bits do not stop root.
* :func:`write_atomically` writes a set of files: all of them or none, the previous output left
  as it was on failure or interrupt, whether or not the output folder is a mount point.
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import signal
import tempfile
from dataclasses import dataclass
from importlib.machinery import EXTENSION_SUFFIXES, SOURCE_SUFFIXES
from keyword import iskeyword
from pathlib import Path
from typing import Sequence

from ..errors import GenerationError, one_line


def module_name(robot_name: str) -> str:
    """The file-name stem of a robot's generated files: a lower-case identifier.

    >>> module_name("UR5 robot"), module_name("7dof")
    ('ur5_robot', 'robot_7dof')
    """
    stem = re.sub(r"[^a-z0-9_]", "_", robot_name.lower().encode("ascii", "replace").decode("ascii"))
    stem = stem.strip("_") or "robot"
    return stem if stem[0].isalpha() else "robot_" + stem


class OutputError(GenerationError):
    """An output path that cannot be written (a file where a folder is needed, a parent that is
    not a folder, a read-only or virtual file system). The message names the path."""


@dataclass(frozen=True)
class GeneratedFile:
    """One output file. ``golden`` files are committed under ``generated/`` and compared by the
    golden test; build products (compiled libraries) are not."""

    name: str
    content: str | bytes
    golden: bool = True


def import_name(file_name: str) -> str | None:
    """The module name under which Python's import system finds the file ``file_name`` in a
    folder on ``sys.path`` (an extension suffix such as ``.cpython-311-x86_64-linux-gnu.so`` or
    a plain ``.so``, or ``.py``), or None for a file it never imports (``.c``, ``.tex``).
    Extension modules come first in the import order: a ``.py`` file and a ``.so`` of one
    import name leave the ``.py`` file unimportable.

    >>> import_name("arm_numpy.py"), import_name("libarm_casadi.so"), import_name("arm.tex")
    ('arm_numpy', 'libarm_casadi', None)
    """
    for suffix in (*EXTENSION_SUFFIXES, *SOURCE_SUFFIXES):
        if file_name.endswith(suffix) and "." not in file_name[:-len(suffix)]:
            return file_name[:-len(suffix)]
    return None


def python_module_name(file_name: str) -> str | None:
    """The module that ``import`` loads from ``file_name``: a ``.py`` file's or an extension
    module's built for this interpreter (its tagged suffix, e.g.
    ``.cpython-311-x86_64-linux-gnu.so``); None for anything else, such as a C library
    (``libarm_casadi.so``), which the import system finds but cannot load.

    >>> python_module_name("arm_numpy.py"), python_module_name("libarm_casadi.so")
    ('arm_numpy', None)
    """
    for suffix in (EXTENSION_SUFFIXES[0], *SOURCE_SUFFIXES):
        if file_name.endswith(suffix) and "." not in file_name[:-len(suffix)]:
            return file_name[:-len(suffix)]
    return None


def import_collisions(file_names: Sequence[str]) -> list[list[str]]:
    """The groups of ``file_names`` that Python would import under one name
    (:func:`import_name`), each sorted: files of one output folder must have none, or the
    second of each group cannot be imported.

    >>> import_collisions(["arm_casadi.py", "arm_casadi.so", "arm_numpy.py", "arm_casadi.c"])
    [['arm_casadi.py', 'arm_casadi.so']]
    """
    groups: dict[str, list[str]] = {}
    for name in file_names:
        module = import_name(name)
        if module is not None:
            groups.setdefault(module, []).append(name)
    return [sorted(group) for _, group in sorted(groups.items()) if len(group) > 1]


def checked_stem(stem: str | None) -> str | None:
    """``stem`` when it can name generated modules (an ASCII Python identifier, not a keyword;
    ``eomgen generate --name``), else a :class:`~eomgen.errors.GenerationError`; None stays None
    (the robot's name, :func:`module_name`)."""
    if stem is None or (stem.isascii() and stem.isidentifier() and not iskeyword(stem)):
        return stem
    raise GenerationError(f"--name: {stem!r} cannot name a Python module (letters, digits and "
                          f"underscores, not starting with a digit, not a keyword)")


def _existing_ancestor(path: Path) -> Path:
    """The nearest of ``path``'s ancestors that exists (``path``'s parent at the closest)."""
    parent = path.parent
    while not os.path.lexists(parent) and parent != parent.parent:
        parent = parent.parent
    return parent


def _problem(exc: OSError, folder: Path) -> str:
    """What refusing to make an entry in ``folder`` with ``exc`` means, in words."""
    if exc.errno == errno.EROFS:
        return f"{folder} is on a read-only file system"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return f"no permission to write in {folder}"
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return f"no space left in {folder}"
    if exc.errno == errno.EFBIG:
        return f"a file in {folder} would pass the largest size this process may write"
    if exc.errno == errno.ENAMETOOLONG:
        return f"a name is longer than the file system allows in {folder}"
    return f"{folder} does not accept new files ({(exc.strerror or str(exc)).lower()})"


def _refuse(path: Path, problem: str) -> OutputError:
    return OutputError(one_line(f"{path}: cannot write the output: {problem}"))


def _probe(folder: Path, path: Path) -> None:
    """Make and remove a folder in ``folder``; raise :class:`OutputError` about ``path`` when
    that fails (the file system refuses new entries there)."""
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".eomgen-probe-", dir=folder))
    except OSError as exc:
        raise _refuse(path, _problem(exc, folder)) from None


def _check_parent(path: Path) -> None:
    """``path``'s missing folders can be made: the nearest existing ancestor is a writable
    folder."""
    ancestor = _existing_ancestor(path)
    if not ancestor.is_dir():
        raise _refuse(path, f"{ancestor} is a file, not a folder")
    _probe(ancestor, path)


def _check_names(path: Path) -> None:
    """Each missing folder or file name of ``path`` fits the file system (``NAME_MAX`` bytes,
    255 on most), so that making it cannot fail with ``ENAMETOOLONG``."""
    ancestor = _existing_ancestor(path)
    try:
        limit = os.pathconf(ancestor, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    missing = path.relative_to(ancestor).parts if path.is_relative_to(ancestor) else path.parts
    for name in missing:
        size = len(os.fsencode(name))
        if size > limit:
            raise _refuse(path, f"the name '{name[:24]}…' is {size} bytes, longer than the "
                                f"{limit} bytes a name may have on this file system")


def check_output_folder(outdir: Path) -> None:
    """Raise :class:`OutputError` unless files can be written into the folder ``outdir``
    (made when missing, with its parents). Nothing is left behind."""
    outdir = Path(outdir)
    _check_names(outdir)
    if os.path.lexists(outdir):
        if not outdir.is_dir():
            raise _refuse(outdir, "it is a file, not a folder")
        _probe(outdir, outdir)
    else:
        _check_parent(outdir)


def check_output_file(path: Path) -> None:
    """Raise :class:`OutputError` unless the file ``path`` can be written (made or replaced;
    its folder made when missing). Nothing is left behind."""
    path = Path(path)
    if path.is_dir():
        raise _refuse(path, "it is a folder, not a file")
    _check_names(path)
    if path.parent.is_dir():
        _probe(path.parent, path)
    else:
        _check_parent(path)


def _make_folders(folder: Path) -> list[Path]:
    """Make ``folder`` and its missing parents; returns those made, deepest last."""
    made = []
    for candidate in [folder, *folder.parents][::-1]:
        if not os.path.lexists(candidate):
            candidate.mkdir()
            made.append(candidate)
    return made


def write_atomically(files: Sequence[GeneratedFile], outdir: Path) -> list[Path]:
    """Write ``files`` into ``outdir``: all of them or, on any failure, none.

    Files are first written into a staging folder on the same file system as their
    destination, so that moving them in is a rename (never a copy, which fails across file
    systems with ``EXDEV``):

    * ``outdir`` missing: the staging folder is made beside it and renamed to ``outdir`` as a
      whole; the parents made for it are removed again on failure.
    * ``outdir`` existing (a mount point such as a container volume included): the staging
      folder is made inside it, a hidden ``.eomgen-staging-*``, and each file is moved in with
      ``os.replace``; files of other names are left alone.

    The moves happen while SIGINT and SIGTERM are held back; the staging folder is always
    removed.
    """
    outdir = Path(outdir)
    try:
        made = _make_folders(outdir.parent)
    except OSError as exc:
        raise _refuse(outdir, _problem(exc, _existing_ancestor(outdir))) from None
    fresh = not os.path.lexists(outdir)
    try:
        if fresh:
            staging = Path(tempfile.mkdtemp(prefix=".eomgen-staging-", dir=outdir.parent))
        else:
            staging = Path(tempfile.mkdtemp(prefix=".eomgen-staging-", dir=outdir))
    except BaseException as exc:
        _remove_folders(made)
        if isinstance(exc, OSError):
            raise _refuse(outdir, _problem(exc, outdir if not fresh else outdir.parent)) from None
        raise
    try:
        for f in files:
            target = staging / f.name
            if isinstance(f.content, bytes):
                target.write_bytes(f.content)
            else:
                target.write_text(f.content, encoding="utf-8", newline="\n")
        if fresh:
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(staging, 0o777 & ~umask)  # mkdtemp made it 0700: as mkdir would
        blocked = {signal.SIGINT, signal.SIGTERM}
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, blocked)
        try:
            if fresh and _rename_folder(staging, outdir):
                staging = None
            else:
                outdir.mkdir(exist_ok=True)
                for f in files:
                    os.replace(staging / f.name, outdir / f.name)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
    except BaseException as exc:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
            staging = None
        if fresh:
            _remove_folders(made)
        if isinstance(exc, OSError):  # a full disk, a name too long: one line, not a traceback
            raise _refuse(outdir, _problem(exc, outdir if not fresh else outdir.parent)) from None
        raise
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
    return [outdir / f.name for f in files]


def _rename_folder(staging: Path, outdir: Path) -> bool:
    """Rename ``staging`` to ``outdir``; False when ``outdir`` appeared meanwhile (then the
    files are moved in one by one)."""
    try:
        os.rename(staging, outdir)
    except OSError as exc:
        if exc.errno in (errno.EEXIST, errno.ENOTEMPTY, errno.EISDIR) or os.path.isdir(outdir):
            return False
        raise
    return True


def _remove_folders(made: list[Path]) -> None:
    """Remove the (empty) folders ``made``, deepest first; ignore those no longer empty."""
    for folder in reversed(made):
        try:
            folder.rmdir()
        except OSError:
            return
