"""Write firmware/src/fill_table.h, the six-chamber firmware's valve-open-time calibration,
from articula's chamber model (developer tool; tests/firmware checks the file is current), or
another actuator's table for `make -C firmware FILL_TABLE=...`.

    python tools/fill_table.py
    python tools/fill_table.py --plant runs/sc/plant.toml --out /tmp/fill.h
"""

from __future__ import annotations

import argparse
from pathlib import Path

from articula.experiments.six_chamber_on_rig import plant_config
from articula.rigs.six_chamber import fill_table_header

HEADER = Path(__file__).resolve().parents[1] / "firmware/src/fill_table.h"

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plant", type=Path, help="a softarm.damping config (its [actuator])")
    parser.add_argument("--out", type=Path, default=HEADER, help="the header to write")
    args = parser.parse_args()
    source = "SixChamberParams defaults" if args.plant is None else f"[actuator] of {args.plant}"
    args.out.write_text(fill_table_header(plant_config(args.plant), source))
    print(f"wrote {args.out}")
