"""The documentation site (mkdocs.yml): docs/*.md and the API reference from the docstrings
build with warnings as errors (a broken link or anchor, a page left out of the nav, a docstring
Griffe cannot read, an API name that no longer exists all fail the build)."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys

import pytest
import yaml

from support import DOCS, ROOT

needs_docs = pytest.mark.skipif(
    any(importlib.util.find_spec(m) is None for m in ("mkdocs", "material", "mkdocstrings")),
    reason="the docs extra is not installed (python3 -m pip install -e \".[docs]\")")


def _mkdocs(*args, cwd=ROOT):
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")  # Material's banner about its successor
    return subprocess.run([sys.executable, "-m", "mkdocs", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


@needs_docs
def test_the_site_builds_with_warnings_as_errors(tmp_path):
    done = _mkdocs("build", "--strict", "--site-dir", str(tmp_path / "site"))
    warnings = [line for line in done.stderr.splitlines() if line.startswith(("WARNING", "ERROR"))]
    assert done.returncode == 0 and warnings == [], done.stderr
    site = tmp_path / "site"
    # the API reference is rendered from the docstrings, not left as ::: directives
    derive = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert "eomgen.dynamics.derive" in derive and ":::" not in derive
    dynamics = (site / "api" / "dynamics" / "index.html").read_text(encoding="utf-8")
    assert "lambdify" in dynamics
    for page in site.glob("api/**/index.html"):  # no Sphinx role is left as it was written
        assert ":mod:" not in page.read_text(encoding="utf-8"), page


@needs_docs
def test_a_broken_link_fails_the_strict_build(tmp_path):
    """The strict build is not a formality: the same configuration with one link to a page
    that does not exist fails."""
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# Home\n\nSee [the missing page](missing.md).\n",
                                   encoding="utf-8")
    config = yaml.load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"), Loader=_IgnoreTags)
    small = {key: config[key] for key in ("site_name", "strict", "validation")}
    small |= {"docs_dir": str(docs), "site_dir": str(tmp_path / "site"), "nav": ["index.md"]}
    (tmp_path / "mkdocs.yml").write_text(yaml.safe_dump(small), encoding="utf-8")
    done = _mkdocs("build", "--strict", cwd=tmp_path)
    assert done.returncode != 0 and "missing.md" in done.stderr


def test_every_docs_page_is_in_the_nav():
    """The nav (mkdocs.yml) lists every page of docs/ and only pages that exist; checked
    without the docs extra too, so a new page that is not in the nav fails everywhere."""
    text = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    config = yaml.load(text, Loader=_IgnoreTags)

    def pages(nav):
        for item in nav:
            value = next(iter(item.values())) if isinstance(item, dict) else item
            yield from (pages(value) if isinstance(value, list) else [value])

    listed = sorted(pages(config["nav"]))
    present = sorted(str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md")
                     if not p.relative_to(DOCS).parts[0].startswith("_"))
    assert listed == present


class _IgnoreTags(yaml.SafeLoader):
    """mkdocs.yml's ``!!python/...`` tags read as None (the nav is all that is read)."""


_IgnoreTags.add_multi_constructor("tag:yaml.org,2002:python/", lambda loader, suffix, node: None)


def test_the_api_reference_shows_sphinx_roles_as_code_and_doctests_as_code_blocks():
    spec = importlib.util.spec_from_file_location("sphinx_roles", DOCS / "_ext" / "sphinx_roles.py")
    if importlib.util.find_spec("griffe") is None:
        pytest.skip("the docs extra is not installed (griffe)")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    text = ("Derive (:func:`eomgen.derive`, :class:`~eomgen.model.RobotModel`)::\n"
            ">>> f([1][2])\n[1]\n\nAfter.\n\nExamples\n--------\n>>> 1 + 1\n2")
    assert module.markdown_docstring(text) == (
        "Derive (`eomgen.derive`, `RobotModel`):\n\n```pycon\n>>> f([1][2])\n[1]\n```\n\n"
        "After.\n\nExamples\n--------\n>>> 1 + 1\n2")
