#!/usr/bin/env bash
# The team study (docs/teams/README.md): conf/experiment/teams.yaml swept in two halves
# (1 and 2 evaders, run side by side on a 2-core machine), then the report with the paired
# comparison of the cooperative team against independent smart pursuers.
# Writes the games into $OUT (default outputs/teams) and the report into docs/teams/report.
set -euo pipefail
OUT=${OUT:-outputs/teams}
N=${N:-40}
PY=${PY:-python}
for m in 1 2; do
  $PY -m pegame -m +experiment=teams game.trials="$N" team.evaders=$m \
    hydra.launcher.n_jobs=1 hydra.sweep.dir="$OUT/evaders$m" &
done
wait
$PY -m pegame.report "$OUT"/evaders1 "$OUT"/evaders2 --out docs/teams/report \
  --compare pursuer=smart,cooperative
