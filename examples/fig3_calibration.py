"""Paper Fig. 3: maximum contact force of two colliding cartridges against Young's modulus,
for the Hertz, Reissner, Hertz–Reissner (eq. 12) and linearised (eqs. 13–15) laws.

Writes ``calibration.csv`` and ``calibration_force_vs_E.png``; the same as
``demfem calibrate``. Run:  python examples/fig3_calibration.py [output directory]
"""
import sys
from pathlib import Path

import numpy as np

from demfem.calibration import force_vs_modulus, write_calibration
from demfem.cartridge import Cartridge


def main(out: Path) -> None:
    table = force_vs_modulus(Cartridge(), np.logspace(7, 11, 25), v_rel=0.2)
    print(table.format())
    for path in write_calibration(out, table):
        print(f"wrote {path}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("demfem_out"))
