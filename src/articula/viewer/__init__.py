"""The browser viewer (viser): replay a planner's run; steer a live one."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "drawing",
    "live",
    "live_plant",
    "live_record",
    "live_scene",
    "painter",
    "replay",
    "run_data",
    "time_plot",
]
