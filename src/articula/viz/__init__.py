"""Matplotlib figures per chapter; imported only where plots are made."""
