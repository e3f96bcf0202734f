"""The derivation cache: the files of an earlier identical generation request, reused.

Deriving a robot and rendering its code takes seconds to minutes; a request answered before is
answered again from the cache in a fraction of that, with the same bytes.

Keys
----
:func:`cache_key` is the SHA-256 of a canonical JSON text of

* the description file's bytes, and a scene file's bytes when one is given;
* the code version (:func:`code_version`): eomgen's ``__version__`` and a fingerprint of its
  sources and templates, so that an edited checkout never serves what older code produced;
* the options: everything else the files depend on (backends, parameters kept symbolic,
  ``strict``, the C compiler found, ...).

Two callers build keys:

* ``eomgen generate`` (:mod:`eomgen.cli`) keys the description *file* (bytes and name) and the
  command's options (:func:`command_request`) before the file is read, so that a hit needs
  neither parsing nor SymPy: the cached run takes a fraction of a second.
* :func:`eomgen.codegen.generate.generate` keys the *model* it is given (a canonical text of
  every name and number, :func:`model_fingerprint`), the backends with the functions
  implementing them, and the description file's bytes (every file's header quotes their hash):
  library callers pass models no file describes (locked joints, substituted parameters).

Storage
-------
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

Only the standard library and eomgen's light modules (output, compiler) are imported at the top
(no SymPy, NumPy or CasADi); the backend registry is imported by :func:`generation_key` alone.
"""

from __future__ import annotations

import base64
import dataclasses
import enum
import hashlib
import hmac
import json
import os
import re
import secrets
import stat
import sys
import warnings
import sysconfig
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Callable, Mapping, Sequence

from .compiler import c_compiler_path
from .errors import recorded_warnings
from .output import GeneratedFile

#: Version of the entry layout; entries of another format are stale.
FORMAT = 1
#: Entries kept; the least recently used beyond are deleted when a new one is stored.
MAX_ENTRIES = 64
#: Description and scene files larger than this are not keyed (the parsers refuse them).
MAX_KEYED_BYTES = 50 * 1024 * 1024

_PACKAGE = Path(__file__).resolve().parent
_KEY = re.compile(r"^[0-9a-f]{64}$")
#: Names a cached file may have: plain file names, no folders, not hidden.
_FILE_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.\-]*$")
#: ``eomgen generate`` parameters that do not change what is written.
COMMAND_IGNORED = frozenset({"description", "outdir", "quiet", "debug", "no_cache", "cache_dir"})
#: ``eomgen generate`` parameters that enter the key (and ``scene_path``, keyed by the scene
#: file's bytes and name). A parameter in none of these, given with a value other than None or
#: False (``--explain``), turns the command-level cache off for that run: it may print more
#: than the files, which a cached run would not repeat.
COMMAND_KEYED = frozenset({"backends", "symbolic", "strict", "no_snap", "outputs", "name"})

Notify = Callable[[str], None]


def _stderr_notice(text: str) -> None:
    print(f"eomgen: notice: {text}", file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------------------------
# Keys
# ----------------------------------------------------------------------------------------------

def default_cache_dir() -> Path:
    """``$EOMGEN_CACHE_DIR``, else ``$XDG_CACHE_HOME/eomgen``, else ``~/.cache/eomgen``."""
    explicit = os.environ.get("EOMGEN_CACHE_DIR")
    if explicit:
        return Path(explicit)
    xdg = os.environ.get("XDG_CACHE_HOME")
    if xdg:
        return Path(xdg) / "eomgen"
    return Path.home() / ".cache" / "eomgen"


@lru_cache(maxsize=1)
def _code_fingerprint() -> str:
    """SHA-256 over eomgen's Python sources and templates (paths and bytes)."""
    digest = hashlib.sha256()
    roots = [_PACKAGE] + [t for t in (_PACKAGE / "templates", _PACKAGE.parent / "templates")
                          if t.is_dir()]
    for root in roots:
        pattern = "*.py" if root == _PACKAGE else "*"
        for path in sorted(root.rglob(pattern)):
            if path.is_file() and "__pycache__" not in path.parts:
                digest.update(str(path.relative_to(root)).encode() + b"\0")
                digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def code_version() -> str:
    """eomgen's ``__version__`` and a fingerprint of its code: ``"0.1.0+3f2a…"``.

    The version alone would serve stale results to anyone editing a checkout (or its
    templates) without bumping it.
    """
    from . import __version__  # read at each call: tests change it

    return f"{__version__}+{_code_fingerprint()[:16]}"


def toolchain() -> dict[str, str | bool | None]:
    """What outside the inputs changes the files: the C compiler the C backends would use
    (:func:`eomgen.compiler.c_compiler_path`), and for the fast backend's compiled extension
    the Python it is built for (its ``EXT_SUFFIX`` names the ABI) and whether Python's headers are there. (NumPy's C API is backward compatible: an
    extension built against NumPy 2 headers targets the oldest supported NumPy by default.)"""
    compiler = c_compiler_path()
    include = sysconfig.get_paths().get("include")
    return {"cc": compiler, "ext_suffix": sysconfig.get_config_var("EXT_SUFFIX"),
            "python_headers": bool(include) and Path(include, "Python.h").is_file()}


def canonical(value) -> object:
    """A JSON-able, deterministic rendering of ``value`` for keys: dataclasses field by field,
    enums by value, SymPy objects by ``srepr``, mappings with sorted keys, paths as text.

    Values of other types are rendered with ``repr``; when that holds a memory address the key
    never matches again, which costs a derivation but never serves a wrong result.
    """
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, bytes):
        return {"sha256": hashlib.sha256(value).hexdigest()}
    if isinstance(value, enum.Enum):
        return [type(value).__name__, canonical(value.value)]
    if isinstance(value, Path):
        return str(value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [type(value).__name__] + [[f.name, canonical(getattr(value, f.name))]
                                         for f in dataclasses.fields(value)]
    if isinstance(value, Mapping):
        return sorted([[canonical(k), canonical(v)] for k, v in value.items()], key=json.dumps)
    if isinstance(value, (list, tuple)):
        return [canonical(v) for v in value]
    if isinstance(value, (set, frozenset)):
        return sorted((canonical(v) for v in value), key=json.dumps)
    if type(value).__module__.startswith("sympy"):
        import sympy  # only for SymPy values, already imported by whoever made them: the
        # cached ``eomgen generate`` path must not load SymPy (start-up time)

        return ["sympy", sympy.srepr(value)]
    return ["repr", repr(value)]


def cache_key(description: bytes, options: Mapping[str, object], scene: bytes | None = None
              ) -> str:
    """The key of a request: SHA-256 (hex) of the description's bytes, the scene's bytes (if
    any), :func:`code_version` and ``options`` (anything :func:`canonical` renders).

    >>> key = cache_key(b"<robot/>", {"backends": ["numpy"]})
    >>> len(key), key == cache_key(b"<robot/>", {"backends": ["numpy"]})
    (64, True)
    >>> key == cache_key(b"<robot/>", {"backends": ["numpy"]}, scene=b"lock: {}")
    False
    """
    text = json.dumps({
        "format": FORMAT,
        "version": code_version(),
        "description": hashlib.sha256(description).hexdigest(),
        "scene": None if scene is None else hashlib.sha256(scene).hexdigest(),
        "options": canonical(dict(options)),
    }, sort_keys=True, ensure_ascii=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def model_fingerprint(model) -> str:
    """SHA-256 of a canonical text of a :class:`~eomgen.model.RobotModel`: every field but
    ``source`` (generated files name the source file only by its base name and hash)."""
    fields = [[f.name, canonical(getattr(model, f.name))]
              for f in dataclasses.fields(model) if f.name != "source"]
    return hashlib.sha256(json.dumps(fields).encode("ascii")).hexdigest()


def _read_limited(path: Path) -> bytes | None:
    """The file's bytes, or None when it is not a readable file of at most MAX_KEYED_BYTES."""
    try:
        if not path.is_file() or path.stat().st_size > MAX_KEYED_BYTES:
            return None
        return path.read_bytes()
    except (OSError, ValueError):
        return None


@dataclass(frozen=True)
class CacheRequest:
    """A key chosen by the caller, and the notices to store with the entry (read when the entry
    is stored, so a list the caller keeps filling may be passed)."""

    key: str
    notices: Sequence[str] = ()


def command_request(description: Path, params: Mapping[str, object]) -> CacheRequest | None:
    """The cache request of an ``eomgen generate`` run, made before the description is read.

    ``params`` are the command's parameters (click's ``ctx.params``). The key covers the
    description file's bytes and name, the scene file's bytes and name (``--scene``; its
    report and the files' headers name it), every parameter of :data:`COMMAND_KEYED`,
    :func:`toolchain` and :func:`code_version`. Returns None (answer without the
    command-level cache) when the description cannot be read or a parameter the cache does not
    know is given.
    """
    description = Path(description)
    data = _read_limited(description)
    if data is None:
        return None
    options: dict[str, object] = {"request": "eomgen generate", "file": description.name,
                                  "toolchain": toolchain()}
    scene = None
    if params.get("scene_path") is not None:
        scene_path = Path(params["scene_path"])
        scene = _read_limited(scene_path)
        if scene is None:
            return None
        options["scene_file"] = scene_path.name
    for name, value in sorted(params.items()):
        if name in COMMAND_IGNORED or name == "scene_path":
            continue
        if name == "name" and value is None:  # keyed only when given: earlier keys stay valid
            continue
        if name not in COMMAND_KEYED:
            if value is None or value is False:
                continue
            return None
        options[name] = value
    return CacheRequest(cache_key(data, options, scene=scene))


def generation_key(model, backends: Sequence[str], options: Mapping[str, object]) -> str:
    """The key of a library call ``render(model, backends, **options)`` (see the module
    docstring): the model's fingerprint, the backends and the functions implementing them,
    the options, the toolchain, and the description file's bytes."""
    # imported here, not at the top: eomgen.codegen loads SymPy, which the cached
    # ``eomgen generate`` path (command_request) must not (start-up time)
    from .codegen import available_backends

    registry = available_backends()
    implementations = [[name, f"{registry[name].generate.__module__}."
                              f"{registry[name].generate.__qualname__}"] for name in backends]
    source = Path(model.source)
    description = _read_limited(source) or b""
    return cache_key(description, {
        "request": "generate()", "file": source.name, "model": model_fingerprint(model),
        "backends": implementations, "options": canonical(dict(options)),
        "toolchain": toolchain(),
    })


# ----------------------------------------------------------------------------------------------
# Storage
# ----------------------------------------------------------------------------------------------

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


# ----------------------------------------------------------------------------------------------
# Use from code generation
# ----------------------------------------------------------------------------------------------

class CachedNotice(UserWarning):
    """A warning the run that filled a cache entry showed while rendering (e.g. that no C
    compiler was found), shown again when a library call is answered from that entry."""


def render_cached(render: Callable[..., list], model, backends: Sequence[str],
                  progress: Callable[[str], None], *, cache: bool | CacheRequest = True,
                  cache_dir: Path | None = None, **options) -> list[GeneratedFile]:
    """``render(model, backends, progress, **options)``, or the files it returned for an
    identical earlier call.

    ``cache`` False calls ``render``; True keys the call with :func:`generation_key`; a
    :class:`CacheRequest` gives the key (and the notices to store) itself. The warnings
    ``render`` shows are stored with the entry too; a call answered from the cache shows them
    again (as :class:`CachedNotice`; ``eomgen generate`` prints an entry's notices itself).
    """
    if cache is False:
        return render(model, backends, progress, **options)
    store = Cache(cache_dir)
    if isinstance(cache, CacheRequest):
        request = cache
    else:
        request = CacheRequest(generation_key(model, backends, options))
    entry = store.get(request.key)
    if entry is not None:
        progress(f"using cached result (key {request.key[:16]}…)")
        if not isinstance(cache, CacheRequest):  # the caller's own notices are not replayed
            for notice in entry.notices:
                warnings.warn(notice, CachedNotice, stacklevel=3)
        return list(entry.files)
    with recorded_warnings(tidy=lambda text: " ".join(text.split())) as shown:
        files = render(model, backends, progress, **options)
    store.put(request.key, files, (*request.notices, *shown))
    return files
