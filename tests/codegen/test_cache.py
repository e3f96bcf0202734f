"""The derivation cache (:mod:`eomgen.cache`): hits and misses, what the key covers, entries
that are truncated, corrupted, tampered with or stale (detected, deleted, rebuilt, never
trusted), the secret's permissions, failures that do not fail a generation, and a cached
``eomgen generate`` that imports neither SymPy nor the parsers.

Every test uses its own cache folder; the suite never touches ``~/.cache`` (``conftest.py``
points ``EOMGEN_CACHE_DIR`` at a temporary folder for every test module).
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
import shutil
import stat
import subprocess
import sys
import sysconfig
import warnings
from pathlib import Path

import pytest

import eomgen
from support import CORPUS, run_cli as run
from eomgen import cache
from eomgen.cache import Cache, CacheRequest, cache_key, command_request, generation_key
from eomgen.codegen import BACKENDS, Backend, GeneratedFile, available_backends
from eomgen.codegen.backends.casadi_backend import c_compiler
from eomgen.codegen.backends.fast_backend import python_headers
from eomgen.codegen.generate import generate
from eomgen.model import lock_joints

ARM = eomgen.example_path("planar_2link")
NOTICE = "eomgen: notice: "


@pytest.fixture
def folder(tmp_path, monkeypatch) -> Path:
    """A fresh cache folder, also the default one (EOMGEN_CACHE_DIR) for this test."""
    path = tmp_path / "cache"
    monkeypatch.setenv("EOMGEN_CACHE_DIR", str(path))
    return path


@pytest.fixture(scope="module")
def arm():
    return eomgen.load(ARM)


def entries(folder: Path) -> list[Path]:
    return sorted((folder / "entries").glob("*.entry"))


def contents(outdir: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(outdir.iterdir())}


def generate_arm(model, outdir: Path, folder: Path, backends: str = "numpy") -> list[str]:
    lines: list[str] = []
    generate(model, outdir, backends, progress=lines.append, cache_dir=folder)
    return lines


# ----------------------------------------------------------------------------------------------
# Hits and misses
# ----------------------------------------------------------------------------------------------

def test_library_miss_then_hit_gives_the_same_files(arm, tmp_path, folder):
    first = generate_arm(arm, tmp_path / "a", folder, "numpy,casadi")
    assert any(line.startswith("deriving") for line in first)
    assert len(entries(folder)) == 1
    second = generate_arm(arm, tmp_path / "b", folder, "numpy,casadi")
    assert len(second) == 1 and second[0].startswith("using cached result (key ")
    assert contents(tmp_path / "a") == contents(tmp_path / "b")
    assert len(entries(folder)) == 1


def test_no_cache_neither_reads_nor_writes(arm, tmp_path, folder):
    lines: list[str] = []
    generate(arm, tmp_path / "a", "numpy", progress=lines.append, cache=False, cache_dir=folder)
    assert not folder.exists()
    generate_arm(arm, tmp_path / "b", folder)
    lines = []
    generate(arm, tmp_path / "c", "numpy", progress=lines.append, cache=False, cache_dir=folder)
    assert any(line.startswith("deriving") for line in lines)


def test_bytes_files_round_trip(folder):
    store = Cache(folder)
    files = [GeneratedFile("a.py", "print('é')\n"), GeneratedFile("b.so", bytes(range(256)), False)]
    key = cache_key(b"x", {})
    assert store.put(key, files, ["a notice"])
    entry = Cache(folder).get(key)
    assert list(entry.files) == files and entry.notices == ("a notice",)


def test_cli_cached_run_prints_and_writes_what_the_first_did(tmp_path, folder):
    first = run("generate", ARM, "--backend", "numpy", "-o", tmp_path / "a")
    assert first.exit_code == 0, first.stderr
    assert "deriving" in first.stderr
    second = run("generate", ARM, "--backend", "numpy", "-o", tmp_path / "a")
    assert second.exit_code == 0, second.stderr
    cached, hint = second.stderr.splitlines()
    assert cached.startswith("eomgen: using cached")
    assert hint == first.stderr.splitlines()[-1]  # how to import, as the first run said
    assert hint.startswith("eomgen: to import, ")
    assert second.stdout == first.stdout
    third = run("generate", ARM, "--backend", "numpy", "-o", tmp_path / "b", "--quiet")
    assert third.stderr == "" and contents(tmp_path / "a") == contents(tmp_path / "b")


def test_cli_cached_run_repeats_the_warnings(tmp_path, folder):
    path = CORPUS / "valid_urdf_triangle_inequality_warns.urdf"
    first = run("generate", path, "--backend", "numpy", "-o", tmp_path / "out")
    warned = [line for line in first.stderr.splitlines() if line.startswith("eomgen: warning:")]
    assert len(warned) == 1 and "triangle inequality" in warned[0]
    second = run("generate", path, "--backend", "numpy", "-o", tmp_path / "out")
    assert "using cached result" in second.stderr
    assert [line for line in second.stderr.splitlines()
            if line.startswith("eomgen: warning:")] == warned


def test_cli_cache_dir_option_and_no_cache(tmp_path, folder):
    other = tmp_path / "other"
    result = run("generate", ARM, "--backend", "numpy", "-o", tmp_path / "o", "--cache-dir", other)
    assert result.exit_code == 0 and len(entries(other)) == 1  # stored under the command's key
    assert not folder.exists()
    again = run("generate", ARM, "--backend", "numpy", "-o", tmp_path / "o", "--cache-dir", other,
                "--no-cache")
    assert "deriving" in again.stderr and "cached" not in again.stderr


def test_options_the_cache_cannot_replay_turn_it_off(tmp_path):
    assert command_request(ARM, {"backends": "numpy", "explain": False}) is not None
    assert command_request(ARM, {"backends": "numpy", "explain": True}) is None
    assert command_request(ARM, {"backends": "numpy", "scene_path": tmp_path / "s.yaml"}) is None
    assert command_request(tmp_path / "missing.urdf", {"backends": "numpy"}) is None


def test_a_cached_cli_run_imports_neither_sympy_nor_the_parsers(tmp_path, folder):
    cache.keys._code_fingerprint.cache_clear()  # the code as the other process will read it
    assert run("generate", ARM, "--backend", "numpy", "-o", tmp_path / "a").exit_code == 0
    script = ("import sys\nfrom eomgen.cli import main\n"
              "try:\n    main(sys.argv[1:])\nexcept SystemExit as exc:\n    code = exc.code\n"
              "heavy = sorted(m for m in ('sympy', 'numpy', 'casadi', 'yaml', 'eomgen.parsers')"
              " if m in sys.modules)\nprint('CODE', code, 'HEAVY', heavy)\n")
    done = subprocess.run([sys.executable, "-c", script, "generate", str(ARM), "--backend",
                           "numpy", "-o", str(tmp_path / "b")], capture_output=True, text=True,
                          timeout=60, env=dict(os.environ, EOMGEN_CACHE_DIR=str(folder)))
    assert "using cached result" in done.stderr, done.stderr
    assert done.stdout.splitlines()[-1] == "CODE 0 HEAVY []", done.stdout
    assert contents(tmp_path / "a") == contents(tmp_path / "b")


# ----------------------------------------------------------------------------------------------
# What the key covers
# ----------------------------------------------------------------------------------------------

def test_key_changes_with_every_input(monkeypatch):
    base = cache_key(b"robot", {"backends": ["numpy"], "symbolic": None, "strict": False})
    assert base == cache_key(b"robot", {"strict": False, "symbolic": None, "backends": ["numpy"]})
    assert base != cache_key(b"robot ", {"backends": ["numpy"], "symbolic": None, "strict": False})
    assert base != cache_key(b"robot", {"backends": ["numpy"], "symbolic": None, "strict": False},
                             scene=b"")
    for changed in ({"backends": ["casadi"], "symbolic": None, "strict": False},
                    {"backends": ["numpy"], "symbolic": ["m1"], "strict": False},
                    {"backends": ["numpy"], "symbolic": [], "strict": False},
                    {"backends": ["numpy"], "symbolic": None, "strict": True}):
        assert base != cache_key(b"robot", changed), changed
    scene = cache_key(b"robot", {}, scene=b"lock: {joint1: 0}")
    assert scene != cache_key(b"robot", {}, scene=b"lock: {joint1: 1}")
    monkeypatch.setattr(eomgen.common.version, "__version__", "99.0")
    assert base != cache_key(b"robot", {"backends": ["numpy"], "symbolic": None, "strict": False})


def test_command_key_covers_file_bytes_name_and_options(tmp_path):
    a = tmp_path / "a.yaml"
    shutil.copy(ARM, a)
    params = {"backends": "numpy", "symbolic": None, "strict": False, "outdir": tmp_path / "x",
              "quiet": False, "debug": False, "no_cache": False, "cache_dir": None,
              "description": a}
    key = command_request(a, params).key
    same = dict(params, outdir=tmp_path / "y", quiet=True, cache_dir=tmp_path)
    assert command_request(a, same).key == key  # what does not change the files
    for name, value in (("backends", "casadi"), ("symbolic", "m1"), ("strict", True)):
        assert command_request(a, dict(params, **{name: value})).key != key, name
    b = tmp_path / "b.yaml"
    shutil.copy(ARM, b)
    assert command_request(b, params).key != key  # the name is in every file's header
    a.write_bytes(a.read_bytes() + b"\n# a comment\n")
    assert command_request(a, params).key != key


def test_library_key_covers_the_model_and_the_backends(arm, monkeypatch):
    key = generation_key(arm, ["numpy"], {"functions": None})
    assert key == generation_key(eomgen.load(ARM), ["numpy"], {"functions": None})
    assert key != generation_key(arm, ["numpy", "casadi"], {"functions": None})
    assert key != generation_key(arm, ["numpy"], {"functions": ("mass_matrix",)})
    assert key != generation_key(lock_joints(arm, {"joint2": 0.5}), ["numpy"], {"functions": None})
    assert key != generation_key(arm.with_numeric_parameters(), ["numpy"], {"functions": None})
    available_backends()
    monkeypatch.setitem(BACKENDS, "numpy", Backend("numpy", "replaced", lambda job: []))
    assert key != generation_key(arm, ["numpy"], {"functions": None})


def test_toolchain_is_the_c_backends_compiler():
    found = c_compiler()
    assert cache.toolchain()["cc"] == (shutil.which(found) if found else None)
    # the fast backend's extension is built for this Python's ABI, with its headers
    assert cache.toolchain()["ext_suffix"] == sysconfig.get_config_var("EXT_SUFFIX")
    assert cache.toolchain()["python_headers"] == (python_headers() is not None)


def test_code_version_changes_with_the_code(monkeypatch):
    version = cache.code_version()
    assert version.startswith(eomgen.__version__ + "+")
    monkeypatch.setattr(cache.keys, "_code_fingerprint", lambda: "f" * 64)
    assert cache.code_version() != version


# ----------------------------------------------------------------------------------------------
# Entries that must not be trusted
# ----------------------------------------------------------------------------------------------

def _stored(arm, tmp_path, folder) -> tuple[Path, dict[str, bytes]]:
    generate_arm(arm, tmp_path / "fresh", folder)
    (entry,) = entries(folder)
    return entry, contents(tmp_path / "fresh")


def _split(entry: Path) -> tuple[dict, bytes]:
    head, _, payload = entry.read_bytes().partition(b"\n")
    return json.loads(head), payload


def _rebuilt(arm, tmp_path, folder, capsys, reason: str, expected: dict[str, bytes]):
    lines = generate_arm(arm, tmp_path / "again", folder)
    assert any(line.startswith("deriving") for line in lines), lines  # not taken from the cache
    notices = [line for line in capsys.readouterr().err.splitlines() if line.startswith(NOTICE)]
    assert len(notices) == 1 and reason in notices[0], notices
    assert "deleted, rebuilding" in notices[0]
    assert contents(tmp_path / "again") == expected
    (entry,) = entries(folder)  # rebuilt, and good again
    assert generate_arm(arm, tmp_path / "third", folder)[0].startswith("using cached result")
    return entry


def test_truncated_entry_is_rebuilt(arm, tmp_path, folder, capsys):
    entry, expected = _stored(arm, tmp_path, folder)
    entry.write_bytes(entry.read_bytes()[:-100])
    _rebuilt(arm, tmp_path, folder, capsys, "truncated", expected)


def test_entry_cut_in_its_header_is_rebuilt(arm, tmp_path, folder, capsys):
    entry, expected = _stored(arm, tmp_path, folder)
    entry.write_bytes(entry.read_bytes()[:30])
    _rebuilt(arm, tmp_path, folder, capsys, "truncated", expected)


def test_corrupted_entry_is_rebuilt(arm, tmp_path, folder, capsys):
    entry, expected = _stored(arm, tmp_path, folder)
    data = bytearray(entry.read_bytes())
    data[-50] ^= 0x01
    entry.write_bytes(bytes(data))
    _rebuilt(arm, tmp_path, folder, capsys, "corrupted (content hash mismatch)", expected)


def test_garbage_entry_is_rebuilt(arm, tmp_path, folder, capsys):
    entry, expected = _stored(arm, tmp_path, folder)
    entry.write_bytes(b"\x80\x04\x95 not json at all\n\x00\x01")
    _rebuilt(arm, tmp_path, folder, capsys, "corrupted (unreadable header)", expected)


def test_tampered_entry_is_rebuilt_not_trusted(arm, tmp_path, folder, capsys):
    """Content changed and its hash updated, as anyone without the secret can: the HMAC fails,
    and the generated file is the derived one, not the planted one."""
    entry, expected = _stored(arm, tmp_path, folder)
    header, payload = _split(entry)
    body = json.loads(payload)
    body["files"][0]["text"] = "import os\nos.system('echo pwned')\n"
    payload = json.dumps(body).encode("ascii")
    header.update(length=len(payload), sha256=hashlib.sha256(payload).hexdigest())
    entry.write_bytes(json.dumps(header).encode("ascii") + b"\n" + payload)
    _rebuilt(arm, tmp_path, folder, capsys, "tampered with (HMAC mismatch", expected)


def test_stale_entry_is_rebuilt(arm, tmp_path, folder, capsys, monkeypatch):
    """An entry written by other code under the same key (here: the code version changes
    between writing and reading) is not used."""
    entry, expected = _stored(arm, tmp_path, folder)
    key = entry.stem
    monkeypatch.setattr(cache.store, "code_version", lambda: "0.0.0+other")  # what get reads
    assert Cache(folder).get(key) is None
    notice = capsys.readouterr().err
    assert "stale (written by eomgen 0.1.0+" in notice and not entry.exists()


def test_entry_of_another_format_is_stale(arm, tmp_path, folder, capsys):
    entry, expected = _stored(arm, tmp_path, folder)
    header, payload = _split(entry)
    header["format"] = 0
    entry.write_bytes(json.dumps(header).encode("ascii") + b"\n" + payload)
    _rebuilt(arm, tmp_path, folder, capsys, "stale (cache format 0", expected)


def test_entry_moved_to_another_key_is_stale(folder, capsys):
    store = Cache(folder)
    one, two = cache_key(b"one", {}), cache_key(b"two", {})
    store.put(one, [GeneratedFile("a.py", "a = 1\n")])
    os.replace(store.path(one), store.path(two))
    assert store.get(two) is None
    assert "stale (stored for another key)" in capsys.readouterr().err


def test_entries_with_unsafe_file_names_are_refused(folder, capsys):
    """Even with a good HMAC (written with the secret), a file name that is a path is never
    written anywhere: the entry is corrupt."""
    store = Cache(folder)
    key = cache_key(b"names", {})
    assert not store.put(key, [GeneratedFile("../escape.py", "x = 1\n")])
    store.put(key, [GeneratedFile("ok.py", "x = 1\n")])
    header, payload = _split(store.path(key))
    body = json.loads(payload)
    body["files"][0]["name"] = "../escape.py"
    payload = json.dumps(body).encode("ascii")
    header.update(length=len(payload), sha256=hashlib.sha256(payload).hexdigest(),
                  hmac=store._mac(payload))
    store.path(key).write_bytes(json.dumps(header).encode("ascii") + b"\n" + payload)
    assert store.get(key) is None
    assert "corrupted (unreadable content)" in capsys.readouterr().err


# ----------------------------------------------------------------------------------------------
# The secret, the folder, failures
# ----------------------------------------------------------------------------------------------

def test_secret_and_entries_are_private(arm, tmp_path, folder):
    generate_arm(arm, tmp_path / "out", folder)
    secret = folder / "secret.key"
    assert stat.S_IMODE(secret.stat().st_mode) == 0o600
    assert len(secret.read_bytes()) == 32
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    assert all(stat.S_IMODE(p.stat().st_mode) == 0o600 for p in entries(folder))
    assert [p.name for p in folder.iterdir() if p.name.startswith(".")] == []  # no temp files


def test_secret_readable_by_others_is_replaced(arm, tmp_path, folder, capsys):
    generate_arm(arm, tmp_path / "out", folder)
    secret = folder / "secret.key"
    old = secret.read_bytes()
    secret.chmod(0o644)
    lines = generate_arm(arm, tmp_path / "again", folder)
    err = capsys.readouterr().err
    assert "is readable or writable by others (mode 0644); replacing it" in err
    assert "tampered with" in err  # the old entry is not trusted under the new secret
    assert any(line.startswith("deriving") for line in lines)
    assert secret.read_bytes() != old and stat.S_IMODE(secret.stat().st_mode) == 0o600


def test_a_symbolic_link_as_secret_is_replaced(arm, tmp_path, folder, capsys):
    generate_arm(arm, tmp_path / "out", folder)
    secret = folder / "secret.key"
    planted = tmp_path / "planted.key"
    planted.write_bytes(b"k" * 32)
    secret.unlink()
    secret.symlink_to(planted)
    generate_arm(arm, tmp_path / "again", folder)
    assert "is a symbolic link; replacing it" in capsys.readouterr().err
    assert not secret.is_symlink() and secret.read_bytes() != b"k" * 32


def test_an_unusable_cache_folder_does_not_fail_generation(arm, tmp_path, capsys):
    blocked = tmp_path / "a_file"
    blocked.write_text("not a folder\n")
    lines = generate_arm(arm, tmp_path / "out", blocked)
    assert any(line.startswith("deriving") for line in lines)
    assert (tmp_path / "out" / "planar_2link_numpy.py").is_file()
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(NOTICE + "cannot write cache entry"), err


def test_least_recently_used_entries_are_pruned(folder, monkeypatch):
    monkeypatch.setattr(cache.store, "MAX_ENTRIES", 2)
    store = Cache(folder)
    keys = [cache_key(bytes([i]), {}) for i in range(3)]
    for i, key in enumerate(keys):
        store.put(key, [GeneratedFile("a.py", f"a = {i}\n")])
        os.utime(store.path(key), (1000 + i, 1000 + i))
    store.put(keys[2], [GeneratedFile("a.py", "a = 2\n")])
    assert sorted(p.stem for p in entries(folder)) == sorted(keys[1:])


def test_default_folder(monkeypatch, tmp_path):
    monkeypatch.setenv("EOMGEN_CACHE_DIR", str(tmp_path / "explicit"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.default_cache_dir() == tmp_path / "explicit"
    monkeypatch.delenv("EOMGEN_CACHE_DIR")
    assert cache.default_cache_dir() == tmp_path / "xdg" / "eomgen"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache.default_cache_dir() == tmp_path / "home" / ".cache" / "eomgen"


def test_the_suite_never_uses_the_users_cache():
    folder = Path(os.environ["EOMGEN_CACHE_DIR"])
    assert cache.default_cache_dir() == folder
    assert Path.home() / ".cache" not in folder.parents


# ----------------------------------------------------------------------------------------------
# No code is ever loaded from the cache
# ----------------------------------------------------------------------------------------------

def test_cache_module_imports_no_deserializer_of_code():
    """Every module of the cache package."""
    imported = set()
    sources = sorted(Path(cache.__file__).parent.glob("*.py"))
    assert {p.stem for p in sources} >= {"__init__", "keys", "store", "generation"}
    nodes = [n for p in sources for n in ast.walk(ast.parse(p.read_text(encoding="utf-8")))]
    for node in nodes:
        if isinstance(node, ast.Import):
            imported |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            imported.add(node.module.split(".")[0])
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            assert node.func.id not in {"eval", "exec", "compile", "__import__"}, node.func.id
    assert not imported & {"pickle", "cPickle", "dill", "cloudpickle", "marshal", "shelve",
                           "joblib", "yaml", "importlib"}, imported


def test_cache_request_key_is_used_as_given(arm, tmp_path, folder):
    key = cache_key(b"chosen", {})
    generate(arm, tmp_path / "out", "numpy", cache=CacheRequest(key, ["a warning"]),
             cache_dir=folder)
    assert [p.stem for p in entries(folder)] == [key]
    assert Cache(folder).get(key).notices == ("a warning",)


def test_warnings_are_not_cached_in_library_entries(tmp_path, folder):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = eomgen.load(CORPUS / "valid_urdf_triangle_inequality_warns.urdf")
    generate(model, tmp_path / "out", "numpy", cache_dir=folder)
    (entry,) = entries(folder)
    assert Cache(folder).get(entry.stem).notices == ()
