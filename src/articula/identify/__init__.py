"""System identification: a rig's recording turned into the constants of its model in articula
(`articula identify`, `articula rig identify`)."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = ["fit", "folders", "motor", "pneunet", "report", "six_chamber"]
