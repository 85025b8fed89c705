"""Any registered experiment, any backend: the registry, run folders, sweeps and the runner."""
