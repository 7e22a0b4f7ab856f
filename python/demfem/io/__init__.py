"""File output that other tools read: atomic writes, strict JSON and VTK particle snapshots
for ParaView."""
from demfem.io.atomic import (atomic_path, clean_stale_temporaries, savefig_atomic,
                              write_bytes_atomic, write_text_atomic)
from demfem.io.strict_json import dumps as json_dumps
from demfem.io.strict_json import finite_or_none, write_json_atomic
from demfem.io.vtk import write_pvd, write_vtk_series, write_vtp

__all__ = ["atomic_path", "clean_stale_temporaries", "savefig_atomic", "write_bytes_atomic",
           "write_text_atomic", "json_dumps", "finite_or_none", "write_json_atomic",
           "write_pvd", "write_vtk_series", "write_vtp"]
