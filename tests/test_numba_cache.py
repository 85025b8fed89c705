"""numba's cache is dropped when compiled sources change (numba itself only sees one file)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from articula.numba_cache import STAMP, refresh_cache, sources_digest
from articula.scene.compiled_clearance import CompiledClearance, _evaluate
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

CONFIGS = Path(__file__).resolve().parents[1] / "src/articula/experiments/configs/ch1"


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
    path = CONFIGS / "circle_two_obstacles.toml"
    scene = build_scene(load_scene_spec(load_toml(path)), path.parent)[0]
    compiled = CompiledClearance.build(scene)
    rng = np.random.default_rng(5)
    for q in rng.uniform(scene.robot.lower, scene.robot.upper, (20, scene.robot.nq)):
        cached = _evaluate(q, *compiled.arrays(), compiled.static_min)
        fresh = _evaluate.py_func(q, *compiled.arrays(), compiled.static_min)
        assert cached[0] == pytest.approx(fresh[0], abs=1e-12)
        assert np.allclose(cached[1], fresh[1], atol=1e-15, rtol=0)
