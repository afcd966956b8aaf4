#!/usr/bin/env bash
# The team study (docs/teams/README.md): pegame/conf/experiment/teams.yaml swept in four parts run
# side by side (one per map), then the report with the paired
# comparison of the cooperative team against independent copies of the smart pursuer.
# Writes the games into $OUT (default outputs/teams) and the report into docs/teams/report.
# N games per cell (seeds 0 .. N-1, shared by every cell).
set -euo pipefail
OUT=${OUT:-outputs/teams}
N=${N:-20}
PY=${PY:-python}
part=0
for maps in office brick enclosed hall; do
  part=$((part + 1))
  $PY -m pegame -m +experiment=teams game.trials="$N" env=$maps team.evaders=1,2 \
    hydra.launcher.n_jobs=1 hydra.sweep.dir="$OUT/part$part" &
done
wait
$PY -m pegame.report "$OUT"/part1 "$OUT"/part2 "$OUT"/part3 "$OUT"/part4 --out docs/teams/report \
  --compare pairing=S-S,cooperative-S
