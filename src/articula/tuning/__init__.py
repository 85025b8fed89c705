"""Model-free tuning: search controller parameters by running experiments."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "coordinate_descent",
    "manual",
    "response",
]
