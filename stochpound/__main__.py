"""``python -m stochpound``: the command-line interface."""

from stochpound.cli import main

main()
