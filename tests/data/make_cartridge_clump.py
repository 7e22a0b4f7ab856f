"""Regenerate tests/data/cartridge_clump_632.csv from the one cartridge geometry.

The Rust tests and benches of the rigid-body core read this fixture so that they run without
Python while still using the beads of ``demfem.cartridge.Cartridge().bead_clump(632)`` (the
single source of the cartridge geometry). Run from the repository root:

    python3 tests/data/make_cartridge_clump.py
"""
import sys
import types
from pathlib import Path

import numpy as np

root = Path(__file__).resolve().parents[2]
# import demfem.cartridge without the compiled extension that demfem/__init__ loads
package = types.ModuleType("demfem")
package.__path__ = [str(root / "python" / "demfem")]
sys.modules["demfem"] = package
from demfem.cartridge import Cartridge  # noqa: E402

clump = Cartridge().bead_clump(632)
table = np.column_stack([clump.centers, clump.radii, clump.masses])
np.savetxt(
    root / "tests" / "data" / "cartridge_clump_632.csv",
    table,
    delimiter=",",
    fmt="%.17g",
    header="x_m,y_m,z_m,radius_m,mass_kg  (Cartridge().bead_clump(632), centres relative to the "
    "cartridge centre of mass, axis z)",
)
