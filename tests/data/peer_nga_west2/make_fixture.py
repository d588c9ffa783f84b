"""Write this folder: a made-up PEER NGA-West2 download (``_SearchResults.csv`` and its ``.AT2`` files).

THE DATA ARE MADE UP. The earthquakes, stations, record sequence numbers
(90001-90005, beyond NGA-West2's) and accelerations are fictitious: seeded
filtered noise under an envelope. Only the layout is PEER's: the search
report's lines, columns and quoting, and the .AT2 header and number format,
as the NGA-West2 web tool writes them (2022-2025 downloads). Run from the
repository's root to write the files again (the same bytes):

    python tests/data/peer_nga_west2/make_fixture.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

FOLDER = Path(__file__).parent
DT = 0.02
NPTS = 300
#: (RSN, earthquake, year, date, station, M, mechanism, Rjb, Rrup, Vs30, Tp (s; None: no pulse), event code, station code, vertical file?)
ROWS = [
    (90001, "Imaginary Valley-01", 2001, "6/15/2001", "Station Alpha", 6.9, "strike slip", 10.2, 12.5, 400.5, None, "IMAGVAL", "ALP", True),
    (90002, "Imaginary Valley-01", 2001, "6/15/2001", "Station Beta", 6.9, "strike slip", 19.8, 21.0, 350.0, 2.104, "IMAGVAL", "BET", True),
    (90003, "Imaginary Valley-01", 2001, "6/15/2001", "Station Gamma_ North", 6.9, "strike slip", 29.4, 30.1, 455.2, None, "IMAGVAL", "GAM", True),
    (90004, "Nowhere_ Atlantis", 1999, "8/17/1999", "Harbour", 7.3, "Reverse", 14.0, 17.3, 520.0, None, "ATLANT", "HBR", False),
    (90005, "Fictional Hills", 2010, "3/2/2010", "Ridge Top", 6.5, "Reverse Oblique", 8.1, 9.6, 610.0, None, "FICTHL", "RDG", True),
]
COMPONENTS = ("000", "090", "-UP")


def motion(rng: np.random.Generator, peak: float, frequency: float) -> np.ndarray:
    """Filtered noise (a damped oscillator's impulse response) under an envelope t·exp(−t/1.2), scaled to ``peak`` g."""
    t = np.arange(NPTS) * DT
    kernel = np.exp(-0.3 * 2 * np.pi * frequency * t[:100]) * np.sin(2 * np.pi * frequency * t[:100])
    values = np.convolve(rng.standard_normal(NPTS), kernel)[:NPTS] * t * np.exp(-t / 1.2)
    return values * peak / np.max(np.abs(values))


def at2_number(value: float) -> str:
    """A sample as NGA-West2 writes it: ``   .9984852E-03`` (a 7-digit mantissa in [0.1, 1), 15 characters)."""
    if value == 0.0:
        return f"{'.0000000E+00':>15s}"
    exponent = int(np.floor(np.log10(abs(value)))) + 1
    digits = int(round(abs(value) / 10.0**exponent * 1e7))
    if digits == 10**7:
        digits, exponent = 10**6, exponent + 1
    return f"{'-' if value < 0 else ''}.{digits:07d}E{exponent:+03d}".rjust(15)


def write_at2(path: Path, title: str, values: np.ndarray) -> None:
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", title, "ACCELERATION TIME SERIES IN UNITS OF G",
             f"NPTS={NPTS:7d}, DT={f'{DT:.4f}'.lstrip('0'):>7s} SEC,".ljust(75)]
    lines += ["".join(at2_number(v) for v in values[i : i + 5]) for i in range(0, NPTS, 5)]
    path.write_text("\n".join(lines) + "\n")


def durations(values: np.ndarray) -> tuple[float, float, float]:
    """D5-75, D5-95 (s) and the Arias intensity (m/s) of a motion in g."""
    cumulative = np.cumsum((values * 9.81) ** 2) * DT
    fraction = cumulative / cumulative[-1]
    at = [np.searchsorted(fraction, q) * DT for q in (0.05, 0.75, 0.95)]
    return at[1] - at[0], at[2] - at[0], float(np.pi / (2 * 9.81) * cumulative[-1])


def main() -> None:
    rng = np.random.default_rng(20261202)
    header = ("Result ID, Spectral Ordinate, Record Sequence Number, Mean Squared Error, Scale Factor, Tp-Pulse Period (sec), "
              "5-75% Duration (sec), 5-95% Duration (sec), Arias Intensity (m/sec), Earthquake Name, Year, Station Name, Magnitude, "
              "Mechanism, Rjb (km), Rrup (km), Vs30 (m/sec), Lowest Useable Frequency (Hz), Initial-search Scale Factor, "
              "Horizontal-1 Acc. Filename, Horizontal-2 Acc. Filename, Vertical Acc. Filename")
    table = []
    for number, (rsn, name, year, date, station, magnitude, mechanism, rjb, rrup, vs30, tp, event, code, vertical) in enumerate(ROWS, start=1):
        files = [f"RSN{rsn}_{event}_{code}{component}.AT2" for component in COMPONENTS]
        peak = 0.45 * np.exp(-rrup / 40.0) * 10 ** (0.3 * (magnitude - 6.9))
        series = [motion(rng, peak * factor, frequency) for factor, frequency in ((1.0, 2.5 - 0.2 * number), (0.8, 3.0 - 0.3 * number), (0.5, 6.0))]
        for file, values, component in zip(files, series, ("0", "90", "UP")):
            if component != "UP" or vertical:
                write_at2(FOLDER / file, f"{name.replace('_ ', ', ')}, {date}, {station.replace('_ ', ', ')}, {component}", values)
        d575, d595, arias = durations(series[0])
        pulse = "-" if tp is None else f"{tp:g}"
        third = files[2] if vertical else " -----  "
        table.append(f"{number}, SRSS, {rsn}, {0.1 * number:.4f}, 1.0, {pulse}, {d575:.1f}, {d595:.1f}, {arias:.1f}, \"{name}\", {year}, "
                     f"\"{station}\", {magnitude:g}, {mechanism}, {rjb:g}, {rrup:g}, {vs30:g}, 0.125, 1.0, {files[0]}, {files[1]} , {third} ")
    spectra = ["Period (sec),Target pSa (g),Arithmetic Mean pSa (g),Arithmetic Mean + Sigma pSa (g),Arithmetic Mean - Sigma pSa (g),"
               + ",".join(f"RSN-{row[0]} SRSS pSa (g)" for row in ROWS)]
    spectra += [f"{period:g}," + ",".join("0.1" for _ in range(4 + len(ROWS))) for period in (0.01, 0.1, 1.0)]  # not read: placeholders
    criteria = ["Magnitude Min:, 6.0", "Magnitude Max:, 7.5", "Rrup Min (km):, 0.0", "Rrup Max (km):, 50.0", "Rjb Min (km):, -1.0e-06",
                "Rjb Max (km):, 99999", "Vs30 Min (m/sec):, 300.0", "Vs30 Max (m/sec):, 700.0", "D9-95 Min (sec):, -1.0e-06",
                "D9-95 Max (sec):, 99999", "Scale Factor Min:, 0.0", "Scale Factor Max:, 5.0", "Period Array:, ", "Weight Array:, ",
                "Record Sequence Number:, ", "Earthquake Name:, ", "Station Name:, ", "User-Defined Maximum Number of Records:, 30",
                "Pulse:, 1", "Damping Ratio:, 0.05", "Scaling Method:, No Scaling", "Suite Average:, Arithmetic",
                "Single-Period-Scaling Period (sec):, ", "Component:, SRSS", "Fault Type:, All Types"]
    notes = [" These records were obtained from the NGA-West2 On-Line Ground-Motion Database Tool", " These records are UNSCALED, AS RECORDED",
             " Filename Extension: ", "   ,AT2 = Acceleration", "   ,VT2 = Velocity", "   ,DT2 = Displacement",
             " MADE-UP TEST DATA: fictitious earthquakes, stations and motions in PEER's layout (tests/data/peer_nga_west2/make_fixture.py)"]
    lines = ["", " PEER Ground Motion Database, Time Series Search Report -- NGA-West2 -- 2026-12-02", "", "",
             " -- Summary of PEER Ground Motion Database Search Criteria --", *criteria, "", "",
             " -- Summary of Metadata of Selected Records --", header, *table, "", *notes, "",
             " -- Scaled Spectra used in Search & Scaling --", *spectra]
    (FOLDER / "_SearchResults.csv").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
