"""The browser viewer (viser): replay a planner's run; steer a live one."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "drawing",
    "live",
    "painter",
    "replay",
    "run_data",
]
