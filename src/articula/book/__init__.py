"""The book's studies, one home per chapter (ch1-ch4), and the report that reproduces them.

Each chapter has the same parts: `experiment` (its registered experiment and config),
`book_values` (what the book prints), `study` (runs the experiments through the shared runner),
`analysis` (pure functions from results to numbers and `Claim`s), `figures` and `report` (only
formatting), and `configs/` (its packaged scene and sweep files). The library never imports
this package.
"""
