"""The ``stochpound`` command-line interface (one module per command group)."""

import click

from stochpound import __version__
from stochpound.cli._group import HelpGroup


@click.group(cls=HelpGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="stochpound")
def main() -> None:
    """Stochastic analysis of earthquake pounding between adjacent buildings."""


def _register() -> None:
    from stochpound.cli._simulate import simulate

    main.add_command(simulate)
    from stochpound.cli._records import records
    main.add_command(records)
    from stochpound.cli._experiment import experiment
    main.add_command(experiment)
    from stochpound.cli._report import report
    main.add_command(report)
    from stochpound.cli._risk import risk
    main.add_command(risk)


_register()
