"""The controller suite: generated tracking problems run by every articula method and by the
peers people already use (mink), side by side."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "mink_model",
    "mink_peer",
    "problems",
    "suite",
]
