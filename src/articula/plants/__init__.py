"""Simulated plants and their sensors: DC motor rigs (ch. 4), the PneuNet (ch. 2), the
six-chamber actuator (ch. 3)."""
