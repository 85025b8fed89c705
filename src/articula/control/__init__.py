"""Discrete controllers, filters and actuator models."""
