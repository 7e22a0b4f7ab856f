"""CalculiX input and output of the resolved contact FEM (:mod:`demfem.stress.resolved_fem`):
the C3D10 (or C3D4) deck of a linear static step with nodal forces and fixed dofs
(:func:`write_calculix_deck`) and the nodal displacements and stresses of its ASCII .frd
(:func:`read_frd`). Written for CalculiX 2.20 (``ccx``, Debian ``calculix-ccx``); the run
itself is :func:`demfem.stress.resolved_fem.run_calculix_case`.

Units: SI (m, N, Pa).
"""
from __future__ import annotations

import os

import numpy as np

from demfem.errors import DemfemError
from demfem.stress.fem_mesh import ResolvedMesh
from demfem.stress.fem_patch import check_material

__all__ = [
    "write_calculix_deck",
    "read_frd",
    "read_frd_stresses",
]


def write_calculix_deck(mesh: ResolvedMesh, E: float, nu: float, loads: np.ndarray,
                        fixed: np.ndarray, title: str = "resolved contact") -> str:
    """A CalculiX 2.20 deck (C3D10 when ``mesh.order`` 2, C3D4 else): linear static step,
    the nodal forces ``loads`` (N, 3) as *CLOAD, the (node, component) pairs ``fixed`` held
    at zero (*BOUNDARY), nodal stresses to the .frd (*EL FILE, S: extrapolated to and
    averaged at the nodes by CalculiX). Node and element numbers are 1-based; numbers carry
    14 significant digits (ccx reads at most 20 characters per field)."""
    E, nu = check_material(E, nu)
    X, T = mesh.nodes, mesh.tets
    etype = "C3D10" if mesh.order == 2 else "C3D4"
    out = [f"** {title}", "*HEADING", title, "*NODE, NSET=NALL"]
    out += [f"{i + 1}, {x[0]:.13e}, {x[1]:.13e}, {x[2]:.13e}" for i, x in enumerate(X)]
    out.append(f"*ELEMENT, TYPE={etype}, ELSET=EALL")
    for e, t in enumerate(T):
        ids = [str(int(v) + 1) for v in t]
        if len(ids) > 8:  # continuation line: at most 16 entries per line, split for safety
            out.append(f"{e + 1}, " + ", ".join(ids[:8]) + ",")
            out.append(", ".join(ids[8:]))
        else:
            out.append(f"{e + 1}, " + ", ".join(ids))
    out += ["*MATERIAL, NAME=GLASS", "*ELASTIC", f"{E:.13e}, {nu:.13e}",
            "*SOLID SECTION, ELSET=EALL, MATERIAL=GLASS", "*STEP", "*STATIC", "*BOUNDARY"]
    out += [f"{int(n) + 1}, {int(c) + 1}, {int(c) + 1}, 0." for n, c in fixed]
    nz = np.flatnonzero(np.any(loads != 0.0, axis=1))
    out.append("*CLOAD")
    for n in nz:
        for c in range(3):
            if loads[n, c] != 0.0:
                out.append(f"{n + 1}, {c + 1}, {loads[n, c]:.13e}")
    out += ["*NODE FILE", "U", "*EL FILE", "S", "*END STEP"]
    return "\n".join(out) + "\n"


def read_frd(path: str | os.PathLike[str], n_nodes: int) -> dict[str, np.ndarray]:
    """Nodal results of the last step in a CalculiX ASCII .frd: ``"U"`` (n_nodes, 3) m and
    ``"S"`` (n_nodes, 6) Pa in demfem's order (xx, yy, zz, yz, xz, xy; CalculiX writes SXX
    SYY SZZ SXY SYZ SZX, extrapolated from the integration points and averaged at nodes)."""
    out = {"U": np.full((n_nodes, 3), np.nan), "S": np.full((n_nodes, 6), np.nan)}
    block = None
    with open(path, "r") as fh:
        for line in fh:
            if line.startswith(" -4"):
                name = line.split()[1]
                block = {"DISP": "U", "STRESS": "S"}.get(name)
                continue
            if block is None:
                continue
            if line.startswith(" -3"):
                block = None
                continue
            if line.startswith(" -1"):
                node = int(line[3:13])
                ncol = 3 if block == "U" else 6
                vals = [float(line[13 + 12 * k:25 + 12 * k]) for k in range(ncol)]
                if block == "S":
                    sxx, syy, szz, sxy, syz, szx = vals
                    vals = [sxx, syy, szz, syz, szx, sxy]
                out[block][node - 1] = vals
    for key, arr in out.items():
        if np.isnan(arr).any():
            raise DemfemError(f"{path}: no {key} values for "
                              f"{int(np.isnan(arr[:, 0]).sum())} nodes")
    return out


def read_frd_stresses(path: str | os.PathLike[str], n_nodes: int) -> np.ndarray:
    """Nodal stresses (n_nodes, 6) Pa of a CalculiX .frd (see :func:`read_frd`)."""
    return read_frd(path, n_nodes)["S"]
