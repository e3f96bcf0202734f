"""Limits: requests too large for the chosen options, and descriptions too large to handle, are
refused at once with a :class:`~eomgen.errors.TooLargeError` saying what would work, instead of
running for hours."""

from __future__ import annotations

import time

import numpy as np
import pytest

import eomgen
from eomgen import dynamics, parsers
from eomgen.errors import DescriptionError, InvalidNumberError, TooLargeError
from eomgen.model.expressions import MAX_MAGNITUDE, parse_scalar
from eomgen.model import MAX_JOINTS, Joint, JointType, Link, build_model
from eomgen.parsers import _yaml

from support.reference import random_robot


def test_simplify_is_refused_above_its_limit_with_the_way_out():
    model = random_robot(np.random.default_rng(3), dynamics.MAX_SIMPLIFY_JOINTS + 1)
    started = time.monotonic()
    with pytest.raises(TooLargeError) as caught:
        eomgen.derive(model, simplify=True)
    assert time.monotonic() - started < 1
    message = str(caught.value)
    assert message.startswith(f"{model.source}: derive(simplify=True): 7 joints: ")
    assert "simplify is limited to 6 joints; use simplify=False" in message
    assert isinstance(caught.value, DescriptionError)
    # the default (None) and False derive the same model without simplifying
    assert not eomgen.derive(model, outputs=("g",)).simplified
    assert not eomgen.derive(model, outputs=("g",), simplify=False).simplified


def test_simplify_is_allowed_up_to_its_limit():
    model = random_robot(np.random.default_rng(3), dynamics.MAX_SIMPLIFY_JOINTS)
    assert eomgen.derive(model, outputs=("g",), simplify=True).simplified


def _chain(joints: int):
    links = [Link("base")] + [Link(f"l{i}") for i in range(1, joints + 1)]
    chain = [Joint(f"j{i}", JointType.FIXED, links[i - 1].name, links[i].name)
             for i in range(1, joints + 1)]
    return links, chain


def test_joint_count_is_capped():
    links, joints = _chain(MAX_JOINTS)
    assert build_model("<chain>", "chain", links, joints).root == "base"
    links, joints = _chain(MAX_JOINTS + 1)
    with pytest.raises(TooLargeError, match=r"<chain>: robot: 501 joints; eomgen handles at "
                                            r"most 500"):
        build_model("<chain>", "chain", links, joints)


def test_joint_count_is_checked_before_reading_yaml_entries(tmp_path):
    """A YAML robot of many joints is refused before any entry is read (the first entry here
    would be an error of its own)."""
    text = ("links:\n  - {name: base, colour: red}\njoints:\n"
            + "".join(f"  - {{name: j{i}}}\n" for i in range(MAX_JOINTS + 1)))
    path = tmp_path / "many.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(TooLargeError, match="501 joints"):
        eomgen.load(path)


def test_file_size_is_capped(tmp_path, monkeypatch):
    monkeypatch.setattr(parsers, "MAX_FILE_BYTES", 100)
    path = tmp_path / "big.urdf"
    path.write_text('<robot name="r"><link name="a"/></robot>' + " " * 100, encoding="utf-8")
    with pytest.raises(TooLargeError, match=r"big.urdf: file larger than 100 bytes"):
        eomgen.load(path)


def test_yaml_node_count_is_a_size_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(_yaml, "MAX_NODES", 50)
    path = tmp_path / "nodes.yaml"
    path.write_text("links:\n" + "".join(f"  - name: l{i}\n" for i in range(40)) + "joints: []\n",
                    encoding="utf-8")
    with pytest.raises(TooLargeError, match="more than 50 nodes"):
        eomgen.load(path)


@pytest.mark.parametrize("text", ["1e101", "-1e101", "1.0000001e12", "-2e12", "10**6*10**7",
                                  "2*" + "9" * 120, 10 ** 400, 1e200])
def test_numbers_beyond_the_magnitude_limit_are_refused(text):
    with pytest.raises(ValueError, match="out of range"):
        parse_scalar(text)


def test_numbers_up_to_the_magnitude_limit_are_read():
    assert MAX_MAGNITUDE == 1e12
    assert float(parse_scalar("1e12")) == MAX_MAGNITUDE
    assert float(parse_scalar("-10**6*10**6")) == -MAX_MAGNITUDE
    assert float(parse_scalar("1e-300")) == 1e-300


def test_a_yaml_integer_beyond_pythons_digit_limit_is_a_number_error(tmp_path):
    path = tmp_path / "digits.yaml"
    path.write_text("links:\n  - name: base\n    mass: " + "1" * 5000 + "\njoints: []\n",
                    encoding="utf-8")
    with pytest.raises(InvalidNumberError, match="too long to read"):
        eomgen.load(path)
