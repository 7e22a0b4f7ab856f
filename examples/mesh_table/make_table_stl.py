"""Write the STL files of the example mesh table (``mesh_table.toml`` names them).

The table is the default accumulation table of demfem (paper Fig. 4: a 0.70 m x 0.34 m
rectangular section, a 0.36 m tilted wall at 45 degrees, an oscillating gate) drawn as a CAD
user would bring it: one STL of the fixed walls in millimetres (the lower side wall, running
on past the gate as the outlet's guide rail, the back wall, a curved guide rail of radius
100 mm rounding the back-upper corner, the upper side wall and the tilted wall; about 10 000
triangles) and one STL of the gate plate, which the scene moves harmonically. Then run::

    python examples/mesh_table/make_table_stl.py
    demfem run examples/mesh_table/mesh_table.toml --out demfem_out/mesh_table

Options: ``--spacing`` (mm, the triangles' size along the walls) and ``--ascii``.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from demfem.io.stl import write_stl
from demfem.scenes.mesh_table import extrude_polyline

HERE = Path(__file__).resolve().parent
# the default table's geometry, m (demfem.scenes.AccumulationTable())
LENGTH, WIDTH, TILTED, ANGLE, HEIGHT = 0.70, 0.34, 0.36, math.radians(45.0), 0.05
OPENING, AMPLITUDE, RADIUS = 0.04, 0.02, 0.00809
X_END = LENGTH + TILTED * math.cos(ANGLE)
Y_TIP = WIDTH - TILTED * math.sin(ANGLE)
RAIL = 0.10  # radius of the curved guide rail at the back-upper corner, m


def wall_plan() -> np.ndarray:
    """The fixed walls' trace on the floor, one polyline (m)."""
    arc = [(RAIL - RAIL * math.cos(a), WIDTH - RAIL + RAIL * math.sin(a))
           for a in np.linspace(0.0, 0.5 * math.pi, 25)]
    return np.array([(X_END + 0.08, 0.0), (0.0, 0.0), *arc, (LENGTH, WIDTH), (X_END, Y_TIP)])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spacing", type=float, default=4.4, help="triangle size, mm (4.4)")
    parser.add_argument("--ascii", action="store_true", help="ASCII STL instead of binary")
    args = parser.parse_args()
    s = args.spacing * 1e-3
    layers = max(1, round(HEIGHT / s))
    v, t = extrude_polyline(wall_plan(), HEIGHT, spacing=s, layers=layers)
    walls = write_stl(HERE / "table_walls.stl", v * 1e3, t, binary=not args.ascii)
    gate_top = Y_TIP + AMPLITUDE + RADIUS
    v, t = extrude_polyline([(X_END, OPENING), (X_END, gate_top)], HEIGHT, spacing=s,
                            layers=layers)
    gate = write_stl(HERE / "gate.stl", v * 1e3, t, binary=not args.ascii)
    print(f"wrote {walls} and {gate}")


if __name__ == "__main__":
    main()
