"""Deprecated path: the Jinja environment moved to :mod:`eomgen.common.templating` (layer 0), which code
generation and the teaching handouts share."""

from ..common.templating import TEMPLATES_DIR, environment, render  # noqa: F401

__all__ = ["TEMPLATES_DIR", "environment", "render"]
