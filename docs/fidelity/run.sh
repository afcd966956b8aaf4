#!/usr/bin/env bash
# The grid side of the fidelity study (README) and its tables: the 27 Table 1 cells of
# +experiment=paper_conditions with simultaneous moves (as the 3D side, run3d.sh), n = $N
# per cell (default 20, seeds 0..N-1: the 3D side's seeds), twice: the oracle with the
# identified profile $PROFILE (default vision_paper_tilt_160, the 3D side's detector and
# camera) and occlusion_miss 0 (the profile's visible factor is its occlusion miss), into
# $OUT/grid; and paper_conditions' own perception model, into $OUT/grid_plain. Then the
# held-out check of the profile and compare.py's tables (run3d.sh first).
set -euo pipefail
# shellcheck source=docs/fidelity/protocol.sh
source "$(dirname "$0")/protocol.sh"
PROFILE=${PROFILE:-vision_paper_tilt_160}
grid grid detector.occlusion_miss=0 detector.profile="$PROFILE"
grid grid_plain
python docs/fidelity/heldout.py
python docs/fidelity/compare.py "$OUT"
