"""``stochpound simulate SCENE.toml --out RUN.nc``: run one scene."""

from __future__ import annotations

from pathlib import Path

import click

from stochpound._atomic import check_not_input, check_writable
from stochpound._errors import StochpoundError, os_error_message
from stochpound.cli._scene_notes import periods_text, say_scene_warnings
from stochpound.results.dataset import write_dataset
from stochpound.model.modal_solution import scene_periods
from stochpound.model.scene_file import load_scene, scene_warnings
from stochpound.solvers.simulate import METHODS, simulate as run_simulation
from stochpound.solvers.ivp import INTEGRATORS


@click.command()
@click.argument("scene_file", type=click.Path(dir_okay=False))
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False), help="Result file (netCDF4/HDF5, suffix .nc).")
@click.option("--overwrite", is_flag=True, help="Replace --out if it exists (otherwise an existing file is refused).")
@click.option("--method", type=click.Choice(METHODS), default=None,
              help="Solver: exact (matrix exponentials) or ivp (scipy integrators); default: exact when every law is piecewise linear, else ivp.")
@click.option("--integrator", type=click.Choice(list(INTEGRATORS)), default="DOP853", show_default=True, help="Integrator of the ivp solver.")
@click.option("--rtol", type=float, default=1e-10, show_default=True, help="Relative tolerance of the ivp solver.")
@click.option("--atol", type=float, default=1e-12, show_default=True, help="Absolute tolerance of the ivp solver (m, m/s).")
@click.option("--demands", is_flag=True, help="Also record floor accelerations, storey drifts and shears, and their peaks.")
def simulate(scene_file: str, out: str, overwrite: bool, method: str | None, integrator: str, rtol: float, atol: float, demands: bool) -> None:
    """Simulate SCENE_FILE and write the result dataset to --out."""
    _check_output(Path(out), overwrite, Path(scene_file))
    try:
        scene = load_scene(scene_file)
        say_scene_warnings(scene_warnings(scene))
        click.echo(f"{scene_file}: periods {periods_text(scene_periods(scene))}")
        result = run_simulation(scene, method, integrator=integrator, rtol=rtol, atol=atol, demands=demands)
        write_dataset(result, out)
    except (StochpoundError, ValueError) as error:
        raise click.ClickException(str(error)) from None
    except OSError as error:
        raise click.ClickException(os_error_message(error)) from None
    n_impacts = result.sizes.get("impact", 0)
    click.echo(
        f"{scene_file}: {len(result.time)} samples, {n_impacts} impacts, "
        f"energy residual {float(abs(result.energy_residual).max()):.3g} J -> {out}"
    )


def _check_output(out: Path, overwrite: bool, scene_file: Path) -> None:
    """Refuse an existing --out without --overwrite, the scene file itself, or one that cannot be written (before anything runs);
    warn on a suffix other than .nc."""
    try:
        check_not_input(out, [(scene_file, "the scene file")], "--out")
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint="--out") from None
    if out.exists() and not overwrite:
        raise click.BadParameter(f"{out} exists; give --overwrite to replace it", param_hint="--out")
    try:
        check_writable(out)
    except OSError as error:
        raise click.ClickException(os_error_message(error)) from None
    if out.suffix != ".nc":
        click.echo(f"warning: --out {out}: the file is netCDF4/HDF5, whose usual suffix is .nc (got {out.suffix or 'none'})", err=True)
