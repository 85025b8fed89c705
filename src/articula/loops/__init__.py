"""Closed loops over time: a plant or an arm, what drives it, and the trace it leaves."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "motor_current",
    "motor_current_linear",
    "online",
    "pneunet_pid",
    "servo",
    "six_chamber",
    "stall",
    "tracking",
]
