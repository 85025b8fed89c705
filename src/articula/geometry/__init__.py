"""Convex shapes (coal), mesh loading and convex decomposition (trimesh, CoACD), bounding
capsules and poses. Distances between shapes live in `articula.scene`."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "bounds",
    "meshes",
    "poses",
    "shapes",
]
