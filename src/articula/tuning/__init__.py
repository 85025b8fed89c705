"""Model-free tuning: search controller parameters by running experiments."""
