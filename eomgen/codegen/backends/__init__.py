"""The code generation backends, found rather than listed: importing this package imports every
module of it whose name ends in ``_backend``, and each registers itself with
:func:`eomgen.codegen.register` where it is defined (printer, config dataclass, template folder
under ``templates/``). Adding a backend is adding such a module; nothing here changes.
"""

import pkgutil
from importlib import import_module

#: Modules that registered a backend when this package was imported, sorted by name.
BACKEND_MODULES = tuple(sorted(info.name for info in pkgutil.iter_modules(__path__)
                               if info.name.endswith("_backend")))

for _name in BACKEND_MODULES:
    import_module(f"{__name__}.{_name}")
