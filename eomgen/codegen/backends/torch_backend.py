"""PyTorch backend: ``<robot>_torch.py``, functions on tensors of any device and dtype, with
autograd through every output.

Printer: the NumPy backend's printer with ``torch.`` as the module prefix (the element-wise
functions the derivations print, ``sin``, ``cos``, ``sqrt``, ``arctan2``, have the same names
in both), so the arithmetic is printed exactly as in the NumPy module. Template:
``templates/torch/module.py.jinja``. The generated module imports only ``torch``; generating it
does not.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...common.output import GeneratedFile
from ..job import Job
from ..registry import register
from ...common.templating import render
from .common import python_loader, python_module_context, warning_exports
from .numpy_backend import ArrayModulePrinter


class TorchModulePrinter(ArrayModulePrinter):
    """``torch`` code: NumPy's element-wise functions under the same names in ``torch``."""

    alias = "torch"


@dataclass(frozen=True)
class TorchConfig:
    """Options of the PyTorch backend."""

    template: str = "torch/module.py.jinja"
    suffix: str = "_torch.py"


@register("torch", "PyTorch module: tensors (n,) or (N, n), any device and dtype, autograd "
                   "(needs torch)", config=TorchConfig, order=70,
          reserved=("torch",), printer=TorchModulePrinter,
          load=python_loader(TorchConfig.suffix), requires=("torch",))
def generate_torch(job: Job, config: TorchConfig = TorchConfig()) -> list[GeneratedFile]:
    printer = TorchModulePrinter({"fully_qualified_modules": True, "standard": "python3"})
    context = python_module_context(job, printer, config.template, warning_exports(job),
                                    backend="torch")
    text = render(config.template, xp=printer.alias, **context)
    return [GeneratedFile(job.stem + config.suffix, text)]
