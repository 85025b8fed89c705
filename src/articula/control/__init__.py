"""Controllers and their parts: PID with gain schedules, PWM, moving-average filter,
chamber allocation and the damping policy."""
