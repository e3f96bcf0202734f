"""Acceptance: every value of a scene made hostile, one at a time.

Three small scenes cover what a scene says (a loop with its plane and actuated joint, couplings
with a ratio and a differential, a contact, locks, a payload, drives, gravity, outputs). Each
leaf value of each is replaced in turn by a value of the wrong kind or range (text, a list, a
mapping, nothing, a negative or zero number, a name that is not there) and the scene applied
as ``eomgen generate --scene`` applies it (:func:`~eomgen.reduction.load_for_scene` then
:func:`~eomgen.reduction.apply_scene`). eomgen must either refuse it, an
:class:`~eomgen.errors.EomgenError` in one line naming the scene file, or apply it to a model
whose float Newton–Euler M and bias are finite at a random state: never another exception,
never a model with a NaN.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import yaml

from eomgen.errors import EomgenError
from eomgen.model.configuration import integrate, neutral
from eomgen.numeric import M_crba, numeric_model, rnea
from eomgen.reduction import apply_scene, load_for_scene
from eomgen.scene import load_scene
from support import ROOT

SCENES = {
    "loop": {"version": 1, "robot": "fourbar",
             "loops": [{"name": "pin", "type": "point",
                        "a": {"link": "rocker", "xyz": [0.5, 0, 0]},
                        "b": {"link": "coupler", "xyz": [0.6, 0, 0]}, "plane": [0, 0, 1]}],
             "actuated": ["crank_joint"]},
    "couplings": {"version": 1, "robot": "elbow_rrr",
                  "couplings": [{"joint": "elbow", "to": "shoulder", "ratio": -1,
                                 "offset": 0.2}],
                  "payloads": [{"link": "link3", "name": "tool", "mass": 0.5,
                                "com": [0.1, 0, 0], "inertia": {"ixx": 0.001, "iyy": 0.001,
                                                                "izz": 0.001}}],
                  "gravity": [0, 0, -9.81], "outputs": ["M", "C", "g"]},
    "contact": {"version": 1, "robot": "planar_2link",
                "contacts": [{"frame": "tip", "normal": [-1, 0, 0]}],
                "actuators": {"joint1": {"armature": 0.05, "damping": 0.2, "friction": 0.3}},
                "locked": {}},
}

#: The description each scene is for.
DESCRIPTIONS = {"loop": ROOT / "examples" / "robots" / "fourbar.yaml",
                "couplings": "elbow_rrr", "contact": "planar_2link"}

#: What replaces a value: the wrong kind, the wrong range, a name that is not there.
HOSTILE = ("", "no_such_name", [], {"x": 1}, None, -1, 0, True)


def _leaves(value, path=()):
    """Paths to every leaf (a scalar, or an empty list or mapping) of a YAML document."""
    if isinstance(value, dict) and value:
        for key, item in value.items():
            yield from _leaves(item, (*path, key))
    elif isinstance(value, list) and value:
        for k, item in enumerate(value):
            yield from _leaves(item, (*path, k))
    else:
        yield path


def _replaced(document, path, value):
    copy = yaml.safe_load(yaml.safe_dump(document))
    target = copy
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return copy


def _cases():
    for scene_name, document in SCENES.items():
        for path in _leaves(document):
            if path in (("version",), ("robot",)):
                continue  # which file: the corpus of descriptions tests those
            for k, value in enumerate(HOSTILE):
                label = "-".join(map(str, path))
                yield pytest.param(scene_name, path, value, id=f"{scene_name}-{label}-{k}")


CASES = list(_cases())


def _apply(name, path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = load_scene(path)
        return apply_scene(load_for_scene(DESCRIPTIONS[name], scene), scene).model


def _check_finite(model) -> None:
    nm = numeric_model(model)
    rng = np.random.default_rng(2)
    q = integrate(neutral(model), rng.uniform(-1, 1, model.dof), 1.0, model)
    qd = rng.uniform(-1, 1, model.dof)
    assert np.all(np.isfinite(M_crba(nm, q)))
    assert np.all(np.isfinite(rnea(nm, q, qd, np.zeros(model.dof))))


def test_the_scenes_apply_and_the_cases_are_many(tmp_path):
    for name, document in SCENES.items():
        path = tmp_path / f"{name}.yaml"
        path.write_text(yaml.safe_dump(document), encoding="utf-8")
        _check_finite(_apply(name, path))
    assert len(CASES) >= 300, len(CASES)


@pytest.mark.parametrize("scene_name, path, value", CASES)
def test_a_hostile_scene_value_is_refused_in_one_line_or_harmless(scene_name, path, value,
                                                                   tmp_path):
    scene_path = tmp_path / "scene.yaml"
    scene_path.write_text(yaml.safe_dump(_replaced(SCENES[scene_name], path, value)),
                          encoding="utf-8")
    try:
        model = _apply(scene_name, scene_path)
    except EomgenError as exc:
        message = str(exc)
        assert "\n" not in message, message
        assert str(scene_path) in message, message
        return
    _check_finite(model)
