"""Closed loops over time: a plant or an arm, what drives it, and the trace it leaves."""
