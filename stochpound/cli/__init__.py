"""The ``stochpound`` command-line interface (one module per command group)."""

import click

from stochpound import __version__
from stochpound.cli.group import HelpGroup


@click.group(cls=HelpGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="stochpound")
def main() -> None:
    """Stochastic analysis of earthquake pounding between adjacent buildings."""


def _register() -> None:
    from stochpound.cli.simulate import simulate

    main.add_command(simulate)
    from stochpound.cli.records import records
    main.add_command(records)
    from stochpound.cli.experiment import experiment
    main.add_command(experiment)
    from stochpound.cli.report import report
    main.add_command(report)
    from stochpound.cli.risk import risk
    main.add_command(risk)


_register()
