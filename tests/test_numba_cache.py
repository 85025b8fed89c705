"""numba_cache.py: `jit` compiles with numba and caches on disk; the cache is dropped when compiled
sources change (numba itself only sees one file)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from articula import numba_cache
from articula.numba_cache import STAMP, jit, refresh_cache, sources_digest
from articula.scene.compiled_clearance import CompiledClearance, _evaluate
from tests.scene.helpers import book_scene

JITTED = """
from articula.numba_cache import jit


@jit()
def total(x):
    s = 0.0
    for v in x:
        s += v
    return s


@jit()
def ratio(a, b):
    return a / b


@jit(error_model="numpy")
def ratio_numpy(a, b):
    return a / b
"""


def _package(tmp_path: Path) -> Path:
    root = tmp_path / "pkg"
    (root / "sub" / "__pycache__").mkdir(parents=True)
    (root / "sub" / "callee.py").write_text("from numba import njit\n")
    (root / "sub" / "plain.py").write_text("x = 1\n")
    return root


def test_cache_files_go_when_a_numba_source_changes(tmp_path):
    root = _package(tmp_path)
    cached = root / "sub" / "__pycache__" / "caller.f-10.py311.nbi"
    cached.write_bytes(b"old")
    assert refresh_cache(root)  # first sight: no stamp, so nothing is trusted
    assert not cached.exists()
    assert (root / "__pycache__" / STAMP).read_text() == sources_digest(root)
    cached.write_bytes(b"fresh")
    assert not refresh_cache(root)  # unchanged sources keep the cache
    assert cached.exists()
    (root / "sub" / "plain.py").write_text("x = 2\n")  # no numba in it: irrelevant
    assert not refresh_cache(root) and cached.exists()
    (root / "sub" / "callee.py").write_text("from numba import njit\n# edited\n")
    assert refresh_cache(root)
    assert not cached.exists()


def test_cached_compiled_chain_equals_a_fresh_composition():
    # _evaluate.py_func runs the Python body, calling the current compiled GJK: a stale cache
    # of _evaluate (built against older GJK code) would differ. (Not bit-equal: the warm
    # starts of the first call move the second's start, and rounding differs by an ulp.)
    scene = book_scene("circle_two_obstacles")
    compiled = CompiledClearance.build(scene)
    rng = np.random.default_rng(5)
    for q in rng.uniform(scene.robot.lower, scene.robot.upper, (20, scene.robot.nq)):
        cached = _evaluate(q, compiled.inputs(), compiled.static_min)
        fresh = _evaluate.py_func(q, compiled.inputs(), compiled.static_min)
        assert cached[0] == pytest.approx(fresh[0], abs=1e-12)
        assert np.allclose(cached[2], fresh[2], atol=1e-15, rtol=0)


def _load(folder: Path, name: str) -> ModuleType:
    """Import JITTED, written to folder/jitted.py (if not there yet), as a module called `name`."""
    path = folder / "jitted.py"
    if not path.exists():
        path.write_text(JITTED)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_jit_function_is_compiled_and_cached_on_disk(tmp_path):
    first = _load(tmp_path, "jitted_first")
    assert first.total(np.arange(4.0)) == 6.0
    assert len(first.total.signatures) == 1  # compiled for float64 arrays
    assert first.total.stats.cache_path == str(tmp_path / "__pycache__")
    assert list((tmp_path / "__pycache__").glob("jitted.total-*.nbi"))
    assert sum(first.total.stats.cache_misses.values()) == 1
    # A new process (here: a new module object) loads the compiled code instead of compiling.
    again = _load(tmp_path, "jitted_again")
    assert again.total(np.arange(4.0)) == 6.0
    assert sum(again.total.stats.cache_hits.values()) == 1
    assert not again.total.stats.cache_misses


def test_jit_passes_its_options_to_numba(tmp_path):
    module = _load(tmp_path, "jitted_options")
    assert module.ratio_numpy(1.0, 0.0) == np.inf  # error_model="numpy"
    with pytest.raises(ZeroDivisionError):
        module.ratio(1.0, 0.0)  # numba's default, Python's error model


@pytest.fixture
def fresh_refresh_once():
    """numba_cache's once-per-process refresh, done for real first, then forgotten for the test
    (and again after it, so that the next jit() call checks the package for real)."""
    numba_cache._refresh_once()
    numba_cache._refresh_once.cache_clear()
    yield
    numba_cache._refresh_once.cache_clear()


def test_jit_refreshes_the_package_cache_once_per_process(monkeypatch, fresh_refresh_once):
    calls = []
    monkeypatch.setattr(numba_cache, "refresh_cache", lambda *args: calls.append(args))
    jit()
    jit(error_model="numpy")
    assert calls == [()]  # the installed package, once


def test_the_cache_is_cold_until_built_from_the_current_sources(tmp_path):
    (tmp_path / "kernels.py").write_text("import numba\n")
    assert numba_cache.is_cold(tmp_path)  # nothing cached
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    (cache / STAMP).write_text(sources_digest(tmp_path), encoding="ascii")
    assert numba_cache.is_cold(tmp_path)  # stamped, but no kernel compiled yet
    (cache / "kernels.total-3.py311.nbi").write_bytes(b"index")
    assert not numba_cache.is_cold(tmp_path)
    (tmp_path / "kernels.py").write_text("import numba  # changed\n")
    assert numba_cache.is_cold(tmp_path)  # the next jit clears it
