"""From the shared arguments to a model: DESCRIPTION (default the bundled planar 2-link arm),
reduced by ``--scene``, checked under ``--strict``; and the file-name stem of a model's outputs.

The parsers, the scene reduction and the code generators import SymPy, so each is imported
when a command needs it: ``import eomgen.cli`` stays light (a cached ``eomgen generate`` is
answered without SymPy).
"""

from __future__ import annotations

from pathlib import Path

import click

from ..common.output import module_name
from ..robots import example_path
from .options import MIMIC_KEY


def default_description() -> Path:
    """The description a command reads without DESCRIPTION: the bundled planar 2-link arm."""
    return example_path("planar_2link")


def load(description: Path | None, strict: bool, scene=None, snap: bool = True):
    """The whole model; warns (refuses under ``strict``) only about what ``scene`` (a loaded
    :class:`eomgen.scene.Scene`, applied by the caller) keeps. ``snap=False`` keeps the
    description's floats exactly (``--no-snap``). Under ``--mimic independent``
    (:func:`mimic_mode`) each follower of a coupling is an independent joint, warned about
    (refused under ``strict``) one by one."""
    from ..parsers import independent_followers  # SymPy, as below
    from ..reduction import load_for_scene  # SymPy: only when a command loads a model

    model = load_for_scene(description or default_description(), scene, strict, snap=snap)
    if mimic_mode() == "independent" and model.couplings:
        model = independent_followers(model, strict, how="--mimic independent")
    return model


def mimic_mode() -> str:
    """``--mimic`` of the running command: ``honour`` (the default) or ``independent``."""
    ctx = click.get_current_context(silent=True)
    return "honour" if ctx is None else ctx.meta.get(MIMIC_KEY, "honour")


def command_params() -> dict:
    """The running command's parameters (click's ``ctx.params``) with ``--mimic`` when given:
    what keys its cached answer (:func:`eomgen.cache.command_request`)."""
    ctx = click.get_current_context()
    mimic = ctx.meta.get(MIMIC_KEY)
    return {**ctx.params, **({"mimic": mimic} if mimic not in (None, "honour") else {})}


def load_reduced(description: Path | None, scene_path: Path | None, strict: bool):
    """``(model, report)``: the description reduced by the scene file (report None without
    one). The scene is read first, so that warnings concern only what it keeps."""
    if scene_path is None:
        return load(description, strict), None
    # SymPy and YAML: only when a command loads a model with a scene
    from ..reduction import apply_scene
    from ..scene import load_scene

    scene = load_scene(scene_path, strict=strict)
    return apply_scene(load(description, strict, scene), scene)


def output_stem(model) -> str:
    """The file-name stem of ``model``'s outputs (``bench_<stem>.md``, ``identify_<stem>.csv``):
    the generated modules' name."""
    return module_name(model.name)
