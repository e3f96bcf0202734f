"""The derivation cache: the files of an earlier identical generation request, reused.

Deriving a robot and rendering its code takes seconds to minutes; a request answered before is
answered again from the cache in a fraction of that, with the same bytes.

* :mod:`eomgen.cache.keys`: what an identical request is (:func:`cache_key` over the
  description's bytes, the code version and the options; :func:`command_request` for
  ``eomgen generate``, :func:`generation_key` for a library call);
* :mod:`eomgen.cache.store`: where its answer is kept (:class:`Cache`: one JSON file per entry,
  signed with the folder's secret, never unpickled; bad entries deleted and rebuilt);
* :mod:`eomgen.cache.generation`: the two put together for code generation
  (:func:`render_cached`).

Only the standard library and eomgen's light modules (output, compiler, errors) are imported
(no SymPy, NumPy or CasADi): a cached ``eomgen generate`` never loads them.
"""

from __future__ import annotations

from .generation import CachedNotice, render_cached
from .keys import (COMMAND_IGNORED, COMMAND_KEYED, FORMAT, MAX_KEYED_BYTES, CacheRequest,
                   cache_key, canonical, code_version, command_request, generation_key,
                   model_fingerprint, toolchain)
from .store import MAX_ENTRIES, Cache, Entry, Notify, cache_folder, default_cache_dir

__all__ = ["COMMAND_IGNORED", "COMMAND_KEYED", "FORMAT", "MAX_ENTRIES", "MAX_KEYED_BYTES",
           "Cache", "CacheRequest", "CachedNotice", "Entry", "Notify", "cache_folder", "cache_key",
           "canonical",
           "code_version", "command_request", "default_cache_dir", "generation_key",
           "model_fingerprint", "render_cached", "toolchain"]
