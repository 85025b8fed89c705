"""Controllers and their parts: PID with gain schedules, PWM, moving-average filter,
chamber allocation and the damping policy."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "chamber_allocation",
    "damping",
    "moving_average",
    "pid",
    "pwm",
]
