"""Write firmware/src/fill_table.h, the six-chamber firmware's valve-open-time calibration,
from articula's chamber model (developer tool; tests/firmware checks the file is current).

    python tools/fill_table.py
"""

from __future__ import annotations

from pathlib import Path

from articula.plants.six_chamber import SixChamberParams
from articula.rigs.six_chamber import fill_table_header

HEADER = Path(__file__).resolve().parents[1] / "firmware/src/fill_table.h"

if __name__ == "__main__":
    HEADER.write_text(fill_table_header(SixChamberParams()))
    print(f"wrote {HEADER}")
