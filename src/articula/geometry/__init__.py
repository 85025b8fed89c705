"""Convex shapes, mesh loading, poses and signed distances (GJK/EPA through coal)."""
