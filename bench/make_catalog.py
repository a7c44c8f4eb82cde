"""Regenerate the bundled catalog of worlds into src/slamtrials/worlds/data/.

Run after any change to the generator that changes its output (and bump GENERATOR_VERSION):

    .venv/bin/python bench/make_catalog.py
"""

from __future__ import annotations

import time
from pathlib import Path

from slamtrials.worlds.catalog_build import build_catalog

DATA = Path(__file__).resolve().parents[1] / "src" / "slamtrials" / "worlds" / "data"


def main() -> None:
    started = time.perf_counter()
    records = build_catalog(DATA)
    for record in records:
        print(
            f"{record['name']:22s} {record['kind']:10s} {record['shape']:9s} "
            f"{record['free_area_m2']:9.1f} m^2  {record['width_m']:6.1f} x {record['height_m']:6.1f} m"
        )
    size = sum(p.stat().st_size for p in DATA.iterdir() if p.is_file())
    print(f"{len(records)} worlds, {size / 1e6:.2f} MB in {DATA}, {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
