"""Explicit finite elements with contact: meshes of cartridges (tets through the wall,
shells on the mid-surface), bodies placed and moving, rigid surfaces (the belt), no-tension
springs to ghost neighbours, an explicit run with progress and Ctrl-C, results as numpy
arrays and VTK files, and the paper's two-cartridge collision (Figs. 2b, 3).

    >>> from demfem.fem import collide_cartridges          # doctest: +SKIP
    >>> r = collide_cartridges(v_rel=0.2, tilt_deg=90)      # doctest: +SKIP
    >>> r.max_force, r.contact_duration                      # doctest: +SKIP
"""
from demfem.fem.collision import CollisionResult, collide_cartridges
from demfem.fem.mesh import (ShellMesh, TetMesh, ball_tet_mesh, cartridge_shell_mesh,
                             cartridge_tet_mesh, estimated_tet_count, rotation_about)
from demfem.fem.model import (Body, ContactOptions, FemModel, GhostSprings, RigidCylinder,
                              RigidPlane, RigidSphere)
from demfem.fem.result import ENERGY_COLUMNS, FemResult, Snapshot, moving_average
from demfem.io.vtk import write_pvd

__all__ = [
    "Body", "CollisionResult", "ContactOptions", "ENERGY_COLUMNS", "FemModel", "FemResult",
    "GhostSprings", "RigidCylinder", "RigidPlane", "RigidSphere", "ShellMesh", "Snapshot",
    "TetMesh", "ball_tet_mesh", "cartridge_shell_mesh", "cartridge_tet_mesh",
    "collide_cartridges", "estimated_tet_count", "moving_average", "rotation_about", "write_pvd",
]
