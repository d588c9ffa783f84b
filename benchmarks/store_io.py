"""Why the store's metadata is created through the netCDF C library: ``python -m benchmarks.store_io [STORE] [--repeat 5]``.

Times, in one run and alternating the two back ends, xarray's two netCDF4/HDF5
engines on an experiment store (by default the quick start's, run into a
temporary folder first):

- *open*: ``xarray.open_dataset(STORE, engine=..., chunks={})`` and close, what
  ``stochpound.open_store`` does (it uses ``h5netcdf``: docs/experiments.md, "The store", says why);
- *create*: ``Dataset.to_netcdf(..., engine=..., compute=False)`` of the store
  opened lazily, which creates every variable's metadata and leaves the data
  unwritten, what the store's writer does before it fills the blocks with h5py
  (it uses ``netcdf4``).

Both engines read the same values (tests/test_experiment_store.py); the
medians of ``repeat`` timings and their ratio are printed as a Markdown table.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import xarray as xr

ENGINES = ("h5netcdf", "netcdf4")


def timings(store: Path, folder: Path, repeat: int) -> dict[str, dict[str, float]]:
    """Median seconds to open ``store`` and to create its metadata in ``folder``, by operation and engine."""
    measured: dict[str, dict[str, list[float]]] = {"open": {e: [] for e in ENGINES}, "create": {e: [] for e in ENGINES}}
    for attempt in range(repeat):
        for engine in ENGINES:  # alternated: a drift of the machine's speed hits both alike
            started = time.perf_counter()
            with xr.open_dataset(store, engine=engine, chunks={}) as data:
                opened = time.perf_counter()
                target = folder / f"{engine}-{attempt}.nc"
                data.to_netcdf(target, engine=engine, compute=False)
                created = time.perf_counter()
            measured["open"][engine].append(opened - started)
            measured["create"][engine].append(created - opened)
            target.unlink()
    return {operation: {e: statistics.median(values) for e, values in by_engine.items()} for operation, by_engine in measured.items()}


def table(store: Path, medians: dict[str, dict[str, float]]) -> str:
    """The Markdown table of :func:`timings`' medians, with the number of the store's variables."""
    with xr.open_dataset(store, engine="netcdf4") as data:
        variables = len(data.variables)
    lines = [f"Store `{store.name}`, {variables} variables.", "", "| operation | h5netcdf (s) | netcdf4 (s) | h5netcdf / netcdf4 |", "|---|---|---|---|"]
    for operation, by_engine in medians.items():
        slow, fast = by_engine["h5netcdf"], by_engine["netcdf4"]
        lines.append(f"| {operation} | {slow:.3f} | {fast:.3f} | {slow / fast:.1f} |")
    return "\n".join(lines)


def _quickstart_store(folder: Path) -> Path:
    """The quick start's experiment run in ``folder``: its store."""
    from stochpound.experiment import load_experiment, run_experiment

    experiment = Path(__file__).parents[1] / "experiments" / "quickstart.toml"
    copy = folder / experiment.name
    copy.write_text(experiment.read_text())
    report = run_experiment(load_experiment(copy), workers=0, progress=False)
    return report.store


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.store_io", description=__doc__.splitlines()[0])
    parser.add_argument("store", nargs="?", type=Path, help="an experiment store (default: the quick start's, run first)")
    parser.add_argument("--repeat", type=int, default=5, help="timings of each operation and engine (default 5)")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error(f"--repeat: must be >= 1, got {args.repeat}")
    with tempfile.TemporaryDirectory() as folder:
        store = args.store or _quickstart_store(Path(folder))
        print(table(store, timings(store, Path(folder), args.repeat)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
