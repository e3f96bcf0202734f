"""eomgen's version, once (``eomgen.__version__`` re-exports it; pyproject.toml states the same
number for the build)."""

__version__ = "0.1.0"
