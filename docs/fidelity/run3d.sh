#!/usr/bin/env bash
# The 3D side of the fidelity study (README): Table 1 of the 3D pipeline with detector=vision
# at the paper's pi/8 tilt (sim.camera_tilt's default) and the articulated person, the
# conditions of docs/paper_conditions/run3d.sh otherwise (simultaneous moves, no occlusion
# miss: the detector's pixels show occlusion), n = $N per cell (default 20, seeds 0..N-1),
# one job at a time ($JOBS, default 1) on the shared machine. The image is 160x120, not the
# default 320x240: a 90 s game costs a third of the CPU time (README), and the profile the
# grid plays (vision_paper_tilt_160) is identified at the same camera. Writes into $OUT/3d
# (default outputs/fidelity). DETECTOR=person plays the person detector instead, at 320x240
# and the tilt $TILT (default 0: level, where it detects at all), into $OUT/3d_person.
# PAIRINGS (default "S-S S-R R-R") picks pairings, e.g. for a second process.
set -euo pipefail
# shellcheck source=docs/fidelity/protocol.sh
source "$(dirname "$0")/protocol.sh"
DETECTOR=${DETECTOR:-vision}
COMMON="$PROTOCOL sim=pybullet detector=$DETECTOR detector.occlusion_miss=0"
DIR=$OUT/3d
if [ "$DETECTOR" = vision ]; then
  COMMON="$COMMON sim.width=160 sim.height=120"
else
  COMMON="$COMMON sim.camera_tilt=${TILT:-0}"
  DIR=$OUT/3d_$DETECTOR
fi
run() {  # run <pairing> <overrides...>
  local dir=$1; shift
  # shellcheck disable=SC2086
  python -m pegame -m $COMMON "$@" hydra.sweep.dir="$DIR/$dir" resume=true
}
declare -A AGENTS=(
  [S-S]="pursuer=smart pursuer.detour=false evader=smart evader.hide_margin=0"
  [S-R]="pursuer=smart pursuer.detour=false evader=random evader.model=action"
  [R-R]="pursuer=random pursuer.model=action evader=random evader.model=action"
)
for pairing in ${PAIRINGS:-S-S S-R R-R}; do
  # shellcheck disable=SC2086
  run "$pairing" ${AGENTS[$pairing]}
done
