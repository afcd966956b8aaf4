#!/usr/bin/env bash
# The factor table of the paper-conditions study: from today's defaults each factor added
# alone, and from +experiment=paper_conditions each factor removed alone, for the pairings
# the factor touches, on the three maps and three speed ratios with seeds 0..N-1 (the same
# seeds as the baselines, so games pair). Writes sweeps into $OUT (default
# outputs/paper_conditions); docs/paper_conditions/factor_table.py turns them into the table.
# Baselines: the defaults' Table 1 sweep ($DEFAULTS, +experiment=paper_table1) and run.sh's
# paper-conditions sweeps ($OUT/table1).
set -euo pipefail
OUT=${OUT:-outputs/paper_conditions}
N=${N:-20}
declare -A PAIR_DEFAULT=(
  [R-R]="pursuer=random evader=random" [S-R]="pursuer=smart evader=random" [S-S]="pursuer=smart evader=smart")
declare -A PAIR_PAPER=(
  [R-R]="pursuer=random pursuer.model=action evader=random evader.model=action"
  [S-R]="pursuer=smart pursuer.detour=false evader=random evader.model=action"
  [S-S]="pursuer=smart pursuer.detour=false evader=smart evader.hide_margin=0")
sweep() {  # sweep <dir> <overrides...>
  local dir=$1; shift
  [ -f "$OUT/$dir/report.json" ] && return 0  # already complete
  python -m pegame -m "$@" game.trials="$N" hydra.sweep.dir="$OUT/$dir" resume=true \
    'env=hall,enclosed,brick' 'game.speed_ratio=0.5,1,2'
}
added() {  # added <factor> <pairings> <overrides...>: the factor alone on today's defaults
  local factor=$1 pairings=$2; shift 2
  for p in $pairings; do
    # shellcheck disable=SC2086
    sweep "added/$factor/$p" ${PAIR_DEFAULT[$p]} "$@" ${EXTRA[$p]:-}
  done
}
removed() {  # removed <factor> <pairings> <overrides...>: paper_conditions without the factor
  local factor=$1 pairings=$2; shift 2
  for p in $pairings; do
    # shellcheck disable=SC2086
    sweep "removed/$factor/$p" +experiment=paper_conditions ${PAIR_PAPER[$p]} "$@"
  done
}
ALL="R-R S-R S-S"
declare -A EXTRA=()
added rate "$ALL" detector.rate=1.0
added latency "$ALL" detector.latency=0.1
added misses "$ALL" detector.occlusion_miss=1.0
added noise "$ALL" detector.range_noise_growth=0.0016
added command_rate "$ALL" game.control_hz=1
added camera_range "$ALL" camera.near=0.05 camera.far=8.0
added turn_order "$ALL" game.turn_order=evader_first
EXTRA=([R-R]="pursuer.model=action evader.model=action" [S-R]="evader.model=action")
added random_model "R-R S-R"
EXTRA=()
added detour "S-R S-S" pursuer.detour=false
added hide_margin "S-S" evader.hide_margin=0
removed rate "$ALL" detector.rate=null
removed latency "$ALL" detector.latency=0.0
removed misses "$ALL" detector.occlusion_miss=0.0
removed camera_range "$ALL" camera.near=0.3 camera.far=5.0
removed turn_order "$ALL" game.turn_order=simultaneous
removed random_model "R-R" pursuer.model=waypoint evader.model=waypoint
removed random_model "S-R" evader.model=waypoint
removed detour "S-R S-S" pursuer.detour=true
removed hide_margin "S-S" evader.hide_margin=0.3
