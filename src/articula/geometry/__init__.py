"""Convex shapes (coal), mesh loading and convex decomposition (trimesh, CoACD), bounding
capsules and poses. Distances between shapes live in `articula.scene`."""
