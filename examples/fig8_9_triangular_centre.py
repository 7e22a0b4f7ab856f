"""Paper Figs. 8-9 at the chosen set-up (A = 2 cm, T = 2 s, V_belt = 0.2 m/s): coordination
and speed of the 'triangular centre' sphere, the 'middle' mean speed of the first line (10 %
of the values cut at each end) with its coordination, table snapshots at 9.3 s and 12.2 s (or
the end of the run), an animated GIF like the paper's Movie 1, and a ParaView series
vtk/table.pvd (point data: index, radius, tag, velocity, force, coordination).

With the same --E and --duration as Fig. 5 the run is the one Fig. 5 already made.

Run:  python examples/fig8_9_triangular_centre.py [--duration 8] [--E 1e7] [--snapshots 9.3,12.2]
                                                  [--quick] [--out DIR]
"""
import sys

from demfem.cli import build_parser, study_options_from_args
from demfem.studies.figures import fig8_9

if __name__ == "__main__":
    args = build_parser().parse_args(["fig8", *sys.argv[1:]])
    fig8_9(study_options_from_args(args),
           snapshot_times=tuple(float(x) for x in args.snapshots.split(",")))
