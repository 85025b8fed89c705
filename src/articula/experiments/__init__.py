"""The book's experiments as configs plus functions, the run records and the sweep runner."""
