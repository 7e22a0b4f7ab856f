"""File output that other tools read: atomic writes and VTK particle snapshots for ParaView."""
from demfem.io.atomic import atomic_path, savefig_atomic, write_bytes_atomic, write_text_atomic
from demfem.io.vtk import write_pvd, write_vtp

__all__ = ["atomic_path", "savefig_atomic", "write_bytes_atomic", "write_text_atomic", "write_pvd", "write_vtp"]
