"""Simulated plants and their sensors: DC motor rigs (ch. 4), the PneuNet (ch. 2), the
six-chamber actuator (ch. 3)."""

# The public modules (imported by name, not here: `import articula` stays light).
__all__ = [
    "dc_motor",
    "motor_rig",
    "motor_sensors",
    "orientation_sensor",
    "pneunet",
    "six_chamber",
    "six_chamber_sim",
]
