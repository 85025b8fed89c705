"""Simulated plants: DC motor rigs (chapter 4)."""
