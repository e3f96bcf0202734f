"""The keys of the derivation cache: what an identical generation request is.

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

Only the standard library and :mod:`eomgen.common.compiler` are imported at the top (no SymPy, NumPy
or CasADi); the backend registry is imported by :func:`generation_key` alone.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import json
import sysconfig
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Mapping, Sequence

from ..common.compiler import c_compiler_path

#: Version of the entry layout; keys and entries of another format are stale.
FORMAT = 1
#: Description and scene files larger than this are not keyed (the parsers refuse them).
MAX_KEYED_BYTES = 50 * 1024 * 1024

#: The package's folder (eomgen/), whose sources and templates the code version covers.
_PACKAGE = Path(__file__).resolve().parents[1]
#: ``eomgen generate`` parameters that do not change what is written.
COMMAND_IGNORED = frozenset({"description", "outdir", "quiet", "debug", "no_cache", "cache_dir",
                             "jobs"})
#: ``eomgen generate`` parameters that enter the key (and ``scene_path``, keyed by the scene
#: file's bytes and name). A parameter in none of these, given with a value other than None or
#: False (``--explain``), turns the command-level cache off for that run: it may print more
#: than the files, which a cached run would not repeat.
COMMAND_KEYED = frozenset({"backends", "symbolic", "strict", "no_snap", "outputs", "name"})


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
    from ..common import version  # read at each call: tests change it

    return f"{version.__version__}+{_code_fingerprint()[:16]}"


def toolchain() -> dict[str, str | bool | None]:
    """What outside the inputs changes the files: the C compiler the C backends would use
    (:func:`eomgen.common.compiler.c_compiler_path`), and for the fast backend's compiled extension
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
    from ..codegen import available_backends

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


__all__ = ["COMMAND_IGNORED", "COMMAND_KEYED", "FORMAT", "MAX_KEYED_BYTES", "CacheRequest",
           "cache_key", "canonical", "code_version", "command_request", "generation_key",
           "model_fingerprint", "toolchain"]
