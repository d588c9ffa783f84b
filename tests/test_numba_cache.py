"""numba's cache of the compiled kernels (stochpound._jit): a read-only installation, and commands that compile nothing.

numba picks where a kernel's cache lives when the kernel is decorated:
``NUMBA_CACHE_DIR``, the source's ``__pycache__``, the user's cache folder.
The tests take away every place but ``NUMBA_CACHE_DIR`` (numba's own
``NUMBA_CACHE_LOCATOR_CLASSES``) and point that under a regular file, which
no one can create a folder in (not even root, who may write in any folder):
numba then finds no writable cache, as on a read-only installation without a
writable home.
"""

from __future__ import annotations

import os
import sys

import numba
import pytest

from stochpound import __version__
from stochpound._jit import FALLBACK_PREFIX
from tests.helpers import cli

needs_locator_choice = pytest.mark.skipif(not hasattr(numba.config, "CACHE_LOCATOR_CLASSES"), reason="numba without NUMBA_CACHE_LOCATOR_CLASSES")


def _no_writable_cache(tmp_path, temporary_writable: bool = True) -> dict[str, str]:
    """The environment of a process for which numba finds no writable cache (and the temporary directory writable or not)."""
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    temporary = tmp_path / "tmp"
    temporary.mkdir(exist_ok=True)
    return {"NUMBA_CACHE_LOCATOR_CLASSES": "UserProvidedCacheLocator", "NUMBA_CACHE_DIR": str(blocker / "cache"),
            "TMPDIR": str(temporary if temporary_writable else blocker / "tmp")}


def _cached_kernels(folder) -> list[str]:
    """The kernels numba's cache in ``folder`` holds (its index files)."""
    return sorted(path.name for path in folder.rglob("*.nbi"))


@needs_locator_choice
@pytest.mark.parametrize("arguments", [["--version"], ["--help"], ["experiment", "run", "--help"]])
def test_without_a_writable_cache_the_commands_answer_with_one_warning_line(tmp_path, arguments):
    """No traceback: the kernels are cached in a private folder of the temporary directory, said in one line; nothing compiled."""
    result = cli(*arguments, env=_no_writable_cache(tmp_path))
    (folder,) = (tmp_path / "tmp").iterdir()
    assert folder.name == f"{FALLBACK_PREFIX}{os.getuid()}" and oct(folder.stat().st_mode & 0o777) == "0o700"
    assert result.stderr == (f"stochpound: numba cannot write its cache of compiled code in {tmp_path / 'a-file' / 'cache'}: "
                             f"caching it in {folder} instead\n"), result.stderr
    assert (result.stdout == f"stochpound, version {__version__}\n") if arguments == ["--version"] else result.stdout.startswith("Usage: ")
    assert _cached_kernels(folder) == []  # --version and --help compile nothing


@needs_locator_choice
def test_without_any_writable_folder_the_kernels_compile_without_a_cache(tmp_path, monkeypatch, caplog):
    """Not even the temporary directory: one line says every process compiles the solver again, and the kernel works uncached."""
    import numpy as np

    from stochpound import _jit

    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setattr(_jit.tempfile, "gettempdir", lambda: str(blocker))
    monkeypatch.setattr(numba.config, "CACHE_LOCATOR_CLASSES", "UserProvidedCacheLocator")
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(blocker / "cache"))
    monkeypatch.setattr(_jit, "fallback_folder", _jit.fallback_folder.__wrapped__)  # not the answer this process keeps
    with caplog.at_level("WARNING", logger="stochpound"):
        kernel = _jit.cached_njit()(lambda values: values.sum())
    assert [record.getMessage() for record in caplog.records] == [
        f"stochpound: numba can write no cache of compiled code ({blocker / 'cache'}; nor the temporary directory: Not a directory): "
        "the solver is compiled again in every process, on first use"]
    assert kernel(np.arange(4.0)) == 6.0 and type(kernel._cache).__name__ == "NullCache"


def test_a_fallback_folder_that_is_not_private_is_not_used(tmp_path, monkeypatch):
    """A folder of that name open to others (someone could plant compiled code in it), or a file of that name, is passed over for a fresh private folder."""
    from stochpound import _jit

    planted = tmp_path / f"{FALLBACK_PREFIX}{os.getuid()}"
    planted.mkdir(mode=0o777)
    planted.chmod(0o777)
    chosen = _jit._private_folder(planted)
    assert chosen != planted and chosen.name.startswith(FALLBACK_PREFIX) and oct(chosen.stat().st_mode & 0o777) == "0o700"
    chosen.rmdir()
    (tmp_path / "a-file").write_text("")
    chosen = _jit._private_folder(tmp_path / "a-file")
    assert chosen.is_dir() and chosen.name.startswith(FALLBACK_PREFIX)
    chosen.rmdir()
    private = tmp_path / "mine"
    assert _jit._private_folder(private) == private and oct(private.stat().st_mode & 0o777) == "0o700"


def test_version_and_help_compile_nothing_into_an_empty_cache(tmp_path):
    """With a writable, empty cache: the commands that only answer leave it empty."""
    cache = tmp_path / "cache"
    for arguments in (["--version"], ["--help"], ["simulate", "--help"]):
        result = cli(*arguments, env={"NUMBA_CACHE_DIR": str(cache)})
        assert result.stderr == "", result.stderr
    assert not cache.exists() or _cached_kernels(cache) == []


@pytest.mark.slow
@needs_locator_choice
def test_without_a_writable_cache_a_simulation_compiles_once_into_the_fallback_folder(tmp_path):
    """A read-only installation: the first process compiles into the fallback folder (two lines: where, and the compile), the
    next loads from it (one line: where); both give the same result as a process with numba's own cache."""
    from stochpound.model.scene_file import scene_from_dict
    from stochpound.solvers.exact import WARM_UP_SCENE, run_exact
    from tests.helpers import REPOSITORY

    code = ("from stochpound.model.scene_file import scene_from_dict\nfrom stochpound.solvers.exact import WARM_UP_SCENE, run_exact\n"
            "print(run_exact(scene_from_dict(WARM_UP_SCENE))[0].states.tobytes().hex())")
    import subprocess

    def run(env: dict[str, str]) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(REPOSITORY), **env},
                              timeout=900)

    environment = _no_writable_cache(tmp_path)
    first, second = run(environment), run(environment)
    assert first.returncode == 0 and second.returncode == 0, (first.stderr, second.stderr)
    first_lines, second_lines = first.stderr.splitlines(), second.stderr.splitlines()
    assert len(first_lines) == 2 and first_lines[1].startswith("stochpound: compiling the exact solver's engine"), first.stderr
    assert second_lines == first_lines[:1], second.stderr  # loaded from the fallback folder: no compile
    (folder,) = (tmp_path / "tmp").iterdir()
    assert any(name.startswith("engine.run_engine") for name in _cached_kernels(folder)), _cached_kernels(folder)
    reference = run_exact(scene_from_dict(WARM_UP_SCENE))[0].states.tobytes().hex()  # this process: numba's own cache, as the session has it
    assert first.stdout == second.stdout == reference + "\n"
