"""Analyses of a recorded run: small functions, numpy in, numpy out, SI units.

Recorded arrays follow one convention: positions and velocities (n_frames, N, 3) in m and m/s,
with NaN rows for spheres that have left the table; contact lists one (n_c, 2) int array per
frame; forces in N; times in s.
"""
from demfem.analysis.collisions import (
    ONSET_DTYPE,
    collision_onset_table,
    onset_histogram,
    onset_quantiles,
)
from demfem.analysis.coordination import (
    contact_pairs_from_positions,
    coordination_from_positions,
    coordination_number,
    coordination_series,
    mean_coordination,
    tag_mask,
)
from demfem.analysis.forces import (
    SETUP_RANKING_DTYPE,
    first_line_force,
    force_statistics,
    gentleness_score,
    mean_tagged_force,
    particle_contact_force,
    rank_setups,
)
from demfem.analysis.kinematics import middle_mean, speed, spheres_riding_up, tagged_speed
from demfem.analysis.order import bond_order, bond_order_psi4, bond_order_psi6, mean_bond_order
from demfem.analysis.oscillation import period_of_oscillation

__all__ = [
    "ONSET_DTYPE",
    "SETUP_RANKING_DTYPE",
    "bond_order",
    "bond_order_psi4",
    "bond_order_psi6",
    "collision_onset_table",
    "contact_pairs_from_positions",
    "coordination_from_positions",
    "coordination_number",
    "coordination_series",
    "first_line_force",
    "force_statistics",
    "gentleness_score",
    "mean_bond_order",
    "mean_coordination",
    "mean_tagged_force",
    "middle_mean",
    "onset_histogram",
    "onset_quantiles",
    "particle_contact_force",
    "period_of_oscillation",
    "rank_setups",
    "speed",
    "spheres_riding_up",
    "tag_mask",
    "tagged_speed",
]
