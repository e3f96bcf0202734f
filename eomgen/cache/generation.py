"""The derivation cache in use: a generation answered from the cache, or rendered and stored
(:func:`render_cached`, what :func:`eomgen.codegen.generate.generate` calls)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Callable, Sequence

from ..errors import recorded_warnings
from ..common.output import GeneratedFile
from .keys import CacheRequest, generation_key
from .store import Cache


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


__all__ = ["CachedNotice", "render_cached"]
