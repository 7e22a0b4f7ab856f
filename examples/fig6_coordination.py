"""Paper Fig. 6: coordination number against time for several Young's moduli E (all spheres,
first line, rectangular centre), V_belt = 0.1 m/s, T = 2 s, A = 2 cm.

Tests the paper's two claims on the recording and prints the numbers: the coordination is
nearly independent of E (mean absolute difference of the all-sphere curve to the one at the
smallest E), and it oscillates between 4 and 6 with the gate's period T (period measured with
demfem.analysis.period_of_oscillation, autocorrelation and FFT, after 2 s; 5-95 % range).

Writes fig6_coordination.png and fig6_findings.json. The runs are shared with Fig. 7.

Run:  python examples/fig6_coordination.py [--duration 8] [--E 1e7,1e8,1e9]
                                           [--stiff-duration S] [--quick] [--out DIR]
      (--stiff-duration: a shorter simulated time for E > 1e9 Pa, e.g. 45e9)
"""
import sys

from demfem.cli import build_parser, durations_from_args, study_options_from_args
from demfem.studies.figures import fig6

if __name__ == "__main__":
    args = build_parser().parse_args(["fig6", *sys.argv[1:]])
    fig6(study_options_from_args(args), stiff_duration=args.stiff_duration,
         durations=durations_from_args(args))
