"""The store of the derivation cache: one signed file per entry, in a private folder.

One file per entry, ``<folder>/entries/<key>.entry``: one line of JSON,
``{"format": 1, "length": n, "sha256": "...", "hmac": "..."}``, then the payload: n bytes of
JSON holding the key, the code version, the files (text, or base64 for bytes, each with its
``golden`` flag) and the notices (warnings) the original run printed. ``hmac`` is HMAC-SHA256
of the payload under the folder's secret (``<folder>/secret.key``: 32 random bytes, mode 0600,
made on first use), ``sha256`` the payload's hash. Nothing is unpickled; the payload is JSON
and is decoded only once its HMAC matched.

An entry that is truncated, corrupted (hash mismatch, bad JSON or shape), tampered with (HMAC
mismatch: not written with this folder's secret) or stale (another format, code version or
key) is never used: it is deleted and rebuilt, with one notice on stderr. A secret that others
can read (or that another user owns) is replaced, which invalidates every entry. Entries are
written to a temporary file and moved in with :func:`os.replace`, so a reader sees a whole entry
or none; the folder keeps the :data:`MAX_ENTRIES` most recently used. Cache failures (a
read-only folder, a full disk) never fail a generation: a notice, and the result is not cached.

The folder is ``--cache-dir``, else ``$EOMGEN_CACHE_DIR``, else ``$XDG_CACHE_HOME/eomgen``, else
``~/.cache/eomgen`` (:func:`default_cache_dir`).
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import hmac
import json
import os
import re
import secrets
import stat
import sys
from contextvars import ContextVar
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator, Sequence

from ..common.output import GeneratedFile
from .keys import FORMAT, code_version

#: Entries kept; the least recently used beyond are deleted when a new one is stored.
MAX_ENTRIES = 64

_KEY = re.compile(r"^[0-9a-f]{64}$")
#: Names a cached file may have: plain file names, no folders, not hidden.
_FILE_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.\-]*$")

Notify = Callable[[str], None]


def _stderr_notice(text: str) -> None:
    print(f"eomgen: notice: {text}", file=sys.stderr, flush=True)


_folder: ContextVar[Path | None] = ContextVar("eomgen_cache_folder", default=None)


@contextlib.contextmanager
def cache_folder(directory: Path | str | None) -> Iterator[None]:
    """Within the block, :func:`default_cache_dir` is ``directory`` (None: unchanged):
    ``generate(..., cache_dir=...)`` sets it, so that what its build steps keep (the fast
    module's compiled objects) goes where the derivation cache does."""
    token = _folder.set(Path(directory) if directory is not None else _folder.get())
    try:
        yield
    finally:
        _folder.reset(token)


def default_cache_dir() -> Path:
    """The folder :func:`cache_folder` set, else ``$EOMGEN_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/eomgen``, else ``~/.cache/eomgen``."""
    if _folder.get() is not None:
        return _folder.get()
    explicit = os.environ.get("EOMGEN_CACHE_DIR")
    if explicit:
        return Path(explicit)
    xdg = os.environ.get("XDG_CACHE_HOME")
    if xdg:
        return Path(xdg) / "eomgen"
    return Path.home() / ".cache" / "eomgen"


@dataclass(frozen=True)
class Entry:
    """What a cache entry holds: the files of a request and the notices its run printed."""

    files: tuple[GeneratedFile, ...]
    notices: tuple[str, ...] = ()


class _Invalid(Exception):
    """An entry that must not be used; ``reason`` says why."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class Cache:
    """The cache folder: :meth:`get` and :meth:`put` entries by key.

    Parameters
    ----------
    directory:
        The folder (default: :func:`default_cache_dir`); created, mode 0700, when first written.
    notify:
        Called with a one-line notice when an entry is discarded or the cache cannot be used
        (default: ``eomgen: notice: ...`` on stderr).
    """

    def __init__(self, directory: Path | str | None = None, notify: Notify | None = None):
        self.directory = Path(directory) if directory is not None else default_cache_dir()
        self.notify = notify or _stderr_notice
        self._secret: bytes | None = None

    @property
    def entries(self) -> Path:
        return self.directory / "entries"

    @property
    def secret_path(self) -> Path:
        return self.directory / "secret.key"

    def path(self, key: str) -> Path:
        if not _KEY.match(key):
            raise ValueError(f"not a cache key: {key!r}")
        return self.entries / f"{key}.entry"

    # -- reading --------------------------------------------------------------------------------

    def get(self, key: str) -> Entry | None:
        """The entry stored under ``key``, or None. An entry that fails any check is deleted
        (with a notice) and None is returned, so that the caller rebuilds it."""
        path = self.path(key)
        try:
            data = path.read_bytes()
        except (FileNotFoundError, NotADirectoryError):  # a miss (put reports a bad folder)
            return None
        except OSError as exc:
            self.notify(f"cannot read cache entry {key[:16]}… ({exc.strerror}); not using it")
            return None
        try:
            entry = self._decode(key, data)
        except _Invalid as exc:
            self._discard(path, key, exc.reason)
            return None
        except OSError as exc:  # the secret could not be read or made
            self.notify(f"cache secret unusable ({exc.strerror}); not using the cache")
            return None
        try:
            os.utime(path)  # most recently used
        except OSError:
            pass
        return entry

    def _decode(self, key: str, data: bytes) -> Entry:
        head, newline, payload = data.partition(b"\n")
        if not newline:
            raise _Invalid("truncated (no header)")
        try:
            header = json.loads(head)
            declared = int(header["length"])
            digest, mac = header["sha256"], header["hmac"]
            version = header["format"]
        except (ValueError, KeyError, TypeError):
            raise _Invalid("corrupted (unreadable header)") from None
        if not all(isinstance(h, str) and _KEY.match(h) for h in (digest, mac)):
            raise _Invalid("corrupted (unreadable header)")
        if version != FORMAT:
            raise _Invalid(f"stale (cache format {version!r}, this eomgen uses {FORMAT})")
        if len(payload) < declared:
            raise _Invalid(f"truncated ({len(payload)} of {declared} bytes)")
        if len(payload) > declared:
            raise _Invalid("corrupted (longer than its header says)")
        if not hmac.compare_digest(hashlib.sha256(payload).hexdigest(), digest):
            raise _Invalid("corrupted (content hash mismatch)")
        if not hmac.compare_digest(self._mac(payload), mac):
            raise _Invalid("tampered with (HMAC mismatch: not written with this cache's secret)")
        try:
            body = json.loads(payload)
            stored_key, stored_version = body["key"], body["version"]
            files = tuple(_decode_file(f) for f in body["files"])
            notices = tuple(body["notices"])
        except (ValueError, KeyError, TypeError, AttributeError):  # binascii.Error is a ValueError
            raise _Invalid("corrupted (unreadable content)") from None
        if not all(isinstance(n, str) for n in notices):
            raise _Invalid("corrupted (unreadable content)")
        if stored_key != key:
            raise _Invalid("stale (stored for another key)")
        if stored_version != code_version():
            raise _Invalid(f"stale (written by eomgen {stored_version})")
        return Entry(files, notices)

    def _discard(self, path: Path, key: str, reason: str) -> None:
        try:
            path.unlink()
        except FileNotFoundError:
            pass
        except OSError as exc:
            self.notify(f"cache entry {key[:16]}… is {reason}; cannot delete it ({exc.strerror})")
            return
        self.notify(f"cache entry {key[:16]}… was {reason}; deleted, rebuilding")

    # -- writing --------------------------------------------------------------------------------

    def put(self, key: str, files: Sequence[GeneratedFile], notices: Sequence[str] = ()) -> bool:
        """Store ``files`` (and ``notices``) under ``key``; False (after a notice) when the cache
        cannot be written. Files with names that are not plain file names are not cached."""
        path = self.path(key)
        if not all(_FILE_NAME.match(f.name) for f in files):
            return False
        payload = json.dumps({
            "key": key,
            "version": code_version(),
            "files": [_encode_file(f) for f in files],
            "notices": [str(n) for n in notices],
        }, sort_keys=True, ensure_ascii=True, separators=(",", ":")).encode("ascii")
        try:
            header = json.dumps({"format": FORMAT, "length": len(payload),
                                 "sha256": hashlib.sha256(payload).hexdigest(),
                                 "hmac": self._mac(payload)}, sort_keys=True)
            _write_atomically(path, header.encode("ascii") + b"\n" + payload)
            self._prune()
        except OSError as exc:
            self.notify(f"cannot write cache entry {key[:16]}… in {self.directory} "
                        f"({exc.strerror}); continuing without the cache")
            return False
        return True

    def _prune(self) -> None:
        """Delete the least recently used entries beyond :data:`MAX_ENTRIES`."""
        found = []
        for path in self.entries.glob("*.entry"):
            try:
                found.append((path.stat().st_mtime, path))
            except OSError:
                continue
        found.sort(reverse=True)
        for _, path in found[MAX_ENTRIES:]:
            try:
                path.unlink()
            except OSError:
                pass

    # -- the secret -----------------------------------------------------------------------------

    def _mac(self, payload: bytes) -> str:
        return hmac.new(self._key(), payload, hashlib.sha256).hexdigest()

    def _key(self) -> bytes:
        if self._secret is None:
            self._secret = self._load_or_make_secret()
        return self._secret

    def _load_or_make_secret(self) -> bytes:
        self.directory.mkdir(parents=True, exist_ok=True, mode=0o700)
        self.entries.mkdir(exist_ok=True, mode=0o700)
        path = self.secret_path
        try:
            descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        except FileNotFoundError:
            return self._make_secret(replace=False)
        except OSError as exc:
            if path.is_symlink():
                self.notify(f"cache secret {path} is a symbolic link; replacing it")
                return self._make_secret(replace=True)
            raise exc
        with os.fdopen(descriptor, "rb") as file:
            info = os.fstat(file.fileno())
            secret = file.read(65)
        problem = _unsafe(info)
        if problem is None and len(secret) != 32:
            problem = "is damaged"
        if problem is not None:
            self.notify(f"cache secret {path} {problem}; replacing it "
                        "(earlier entries will be rebuilt)")
            return self._make_secret(replace=True)
        return secret

    def _make_secret(self, replace: bool) -> bytes:
        """A new random secret, written with mode 0600; when another process made one first
        (and ``replace`` is False), that one."""
        secret = secrets.token_bytes(32)
        temporary = _write_private(self.directory, secret)
        try:
            if replace:
                os.replace(temporary, self.secret_path)
                return secret
            try:
                os.link(temporary, self.secret_path)  # fails if another process won the race
                return secret
            except FileExistsError:
                return self._load_or_make_secret()
            except OSError:  # a file system without hard links
                os.replace(temporary, self.secret_path)
                return secret
        finally:
            try:
                os.unlink(temporary)
            except FileNotFoundError:
                pass


def _unsafe(info: os.stat_result) -> str | None:
    """Why a secret file with this status cannot be trusted, or None."""
    if not stat.S_ISREG(info.st_mode):
        return "is not a regular file"
    if hasattr(os, "getuid") and info.st_uid != os.getuid():
        return "belongs to another user"
    if os.name == "posix" and info.st_mode & 0o077:
        return f"is readable or writable by others (mode {stat.S_IMODE(info.st_mode):04o})"
    return None


def _write_private(folder: Path, data: bytes) -> Path:
    """Write ``data`` to a new file (mode 0600) in ``folder``; returns its path."""
    path = folder / f".tmp-{secrets.token_hex(8)}"
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        with os.fdopen(descriptor, "wb") as file:
            file.write(data)
            file.flush()
            os.fsync(file.fileno())
    except BaseException:
        path.unlink(missing_ok=True)
        raise
    return path


def _write_atomically(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and :func:`os.replace`."""
    temporary = _write_private(path.parent, data)
    try:
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def _encode_file(f: GeneratedFile) -> dict:
    if isinstance(f.content, bytes):
        return {"name": f.name, "golden": f.golden,
                "base64": base64.b64encode(f.content).decode("ascii")}
    return {"name": f.name, "golden": f.golden, "text": f.content}


def _decode_file(data: dict) -> GeneratedFile:
    name, golden = data["name"], data["golden"]
    if not isinstance(name, str) or not _FILE_NAME.match(name) or not isinstance(golden, bool):
        raise ValueError("bad file entry")
    if "text" in data and "base64" not in data and isinstance(data["text"], str):
        return GeneratedFile(name, data["text"], golden)
    if "base64" in data and "text" not in data and isinstance(data["base64"], str):
        return GeneratedFile(name, base64.b64decode(data["base64"], validate=True), golden)
    raise ValueError("bad file entry")


__all__ = ["MAX_ENTRIES", "Cache", "Entry", "Notify", "cache_folder", "default_cache_dir"]
