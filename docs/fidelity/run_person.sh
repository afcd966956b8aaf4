#!/usr/bin/env bash
# The person detector's part of the fidelity study (README, "The person detector"): after
# `DETECTOR=person N=10 bash docs/fidelity/run3d.sh` (the 3D side, level camera), its
# Table 1 report into docs/fidelity/table1_person, and the grid twin: the oracle with the
# profile person_level identified on the 3D pipeline at the same camera, occlusion_miss 0,
# into $OUT/grid_person; then compare.py's tables. N must be the 3D side's.
set -euo pipefail
# shellcheck source=docs/fidelity/protocol.sh
source "$(dirname "$0")/protocol.sh"
python -m pegame.report "$OUT"/3d_person/S-S "$OUT"/3d_person/S-R "$OUT"/3d_person/R-R \
  --out docs/fidelity/table1_person
grid grid_person detector.occlusion_miss=0 detector.profile=person_level
python docs/fidelity/compare.py "$OUT"
