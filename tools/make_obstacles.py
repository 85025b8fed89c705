"""Write the example obstacle meshes of chapter 1 (developer tool; deterministic).

    python tools/make_obstacles.py

bracket.stl: an L-shaped bracket (non-convex, two boxes); rock.stl: an irregular, non-convex
blob (an icosphere with radial bumps). Both in metres, centred near their frame origin.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

OUT = Path(__file__).resolve().parents[1] / "src/articula/book/ch1/configs"


def bracket() -> trimesh.Trimesh:
    """An L bracket: a 0.24 × 0.06 × 0.30 m plate and a 0.24 × 0.20 × 0.06 m foot."""
    plate = trimesh.creation.box((0.24, 0.06, 0.30))
    foot = trimesh.creation.box((0.24, 0.20, 0.06))
    foot.apply_translation((0.0, -0.07, -0.12))
    return trimesh.util.concatenate([plate, foot])


def rock() -> trimesh.Trimesh:
    """A lumpy blob of about 0.2 m across."""
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=0.1)
    rng = np.random.default_rng(7)
    directions = rng.normal(size=(6, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    unit = mesh.vertices / np.linalg.norm(mesh.vertices, axis=1, keepdims=True)
    bumps = np.exp(8.0 * (unit @ directions.T - 1.0)) @ rng.uniform(-0.35, 0.35, size=6)
    return trimesh.Trimesh(mesh.vertices * (1.0 + bumps)[:, None], mesh.faces)


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    bracket().export(OUT / "bracket.stl")
    rock().export(OUT / "rock.stl")
