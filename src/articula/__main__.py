"""`python -m articula` runs the command line."""

from articula.cli import main

main()
