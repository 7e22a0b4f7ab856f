"""Scenes: parameter objects that build engine-neutral descriptions of a DEM set-up."""
from demfem.scenes.cluster import CartridgeCluster  # noqa: F401  (FEM cluster, Figs. 10-13)
from demfem.scenes.table import (
    TAG_NAMES,
    AccumulationTable,
    SceneDescription,
    Tag,
    wall_displacement,
    wall_velocity,
)

__all__ = [
    "TAG_NAMES",
    "AccumulationTable",
    "SceneDescription",
    "Tag",
    "wall_displacement",
    "wall_velocity",
]
