"""The code generation backends; importing this package registers them all."""

from importlib import import_module

#: Modules that register a backend when imported.
BACKEND_MODULES = ("numpy_backend", "casadi_backend", "fast_backend", "latex_backend",
                   "jax_backend", "torch_backend")

for _name in BACKEND_MODULES:
    try:
        import_module(f"{__name__}.{_name}")
    except ModuleNotFoundError as exc:  # a backend still being written
        if exc.name != f"{__name__}.{_name}":
            raise
