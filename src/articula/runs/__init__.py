"""Any registered experiment, any backend: the registry, run folders, sweeps and the runner."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "backends",
    "folders",
    "records",
    "registry",
    "runner",
    "sweep",
]
