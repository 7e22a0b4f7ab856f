"""Equivalent spheres vs clumped and exact cartridges on the same reduced accumulation table.

Usage: python examples/equivalence_study.py [--out demfem_out/equivalence] [--t-end 2.0]
(the same as ``demfem equivalence``). Writes equivalence.csv, .md and .png; see
:mod:`demfem.equivalence` for what is compared.
"""
import sys

from demfem.cli import main

if __name__ == "__main__":
    sys.exit(main(["equivalence", *sys.argv[1:]]))
