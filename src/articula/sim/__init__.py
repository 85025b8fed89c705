"""Simulated hardware: the arm under rigid-body dynamics (MuJoCo), the `sim` extra."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = ["twin", "twin_arm"]
