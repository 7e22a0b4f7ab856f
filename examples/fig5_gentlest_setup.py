"""Paper Fig. 5: first-line average force against time for the gate amplitude A, period T and
belt speed V_belt of the paper, and the gentlest set-up by an explicit criterion.

Panels: (a) V_belt = 0.2 m/s, T = 1 s, A in {1, 2, 5, 7.5} cm; (b) V_belt = 0.3 m/s, A = 5 cm,
T in {0.5, 1, 2} s; (c) T = 2 s, A = 5 cm, V_belt in {0.1, 0.2, 0.3} m/s; plus the paper's
choice A = 2 cm, T = 2 s, V_belt = 0.2 m/s. All on one geometry (tilted wall 0.24 m, narrowest
opening 2 cm), run on a Dask LocalCluster (one run per worker, finished runs reused). The runs
are ranked by demfem.analysis.gentleness_score: mean, peak and 95 % quantile of the first-line
force after 1 s, each relative to the median run.

Writes fig5_first_line_force.png, fig5_ranking.txt/.csv into the output folder.

Run:  python examples/fig5_gentlest_setup.py [--duration 8] [--E 1e7] [--quick] [--out DIR]
      (the same as `demfem fig5 ...`)
"""
import sys

from demfem.cli import build_parser, study_options_from_args
from demfem.studies.figures import fig5

if __name__ == "__main__":
    args = build_parser().parse_args(["fig5", *sys.argv[1:]])
    result = fig5(study_options_from_args(args), discard_before=args.discard_before)
    print(f"gentlest set-up: {result['gentlest']} (paper: A=2cm T=2s V=0.2m/s)")
