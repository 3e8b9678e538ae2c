#!/usr/bin/env bash
# Fig. 5 / Fig. 7 evidence on a GPU machine without Ray: the Fig. 6
# encoders stacked, flare and dual_interactive (same losses, `--agent.recipe`) trained with
# `simoun-train --preset cpu` on dm_control cartpole-swingup for STUDY_STEPS env steps, SEEDS,
# side by side; then `simoun-analyze bias` over the seed-1 runs and `simoun-analyze masks` of the
# dual_interactive one. Logs, CSVs and analyses (no checkpoints) go to $OUT/bias.tgz.
set -u
steps=${STUDY_STEPS:-16000}
root=${STUDY_DIR:-/tmp/bias-study}
out=${OUT:-/tmp/out}
analyze="python3 -m simoun_lab.cli.analyze"
mkdir -p "$root" "$out"
for encoder in stacked flare dual_interactive; do
  for seed in ${SEEDS:-1 2 3}; do
    timeout "${STUDY_SECONDS:-240}" python3 -m simoun_agent.run.train --preset cpu \
      --agent.recipe "$encoder" --total-env-steps "$steps" --eval-every 8000 \
      --eval-episodes 5 --checkpoint-every 8000 --video false --progress false \
      --seed "$seed" --run-dir "$root/$encoder/s$seed" >"$root/$encoder-s$seed.log" 2>&1 &
  done
done
wait
$analyze bias "$root"/stacked/s1 "$root"/flare/s1 "$root"/dual_interactive/s1 \
  --recolour model --out "$root/analysis/bias" >"$root/bias.log" 2>&1
$analyze masks "$root"/dual_interactive/s1 --steps 2,20,60 --query 24,24 --video \
  --out "$root/analysis/masks" >"$root/masks.log" 2>&1
tar czf "$out/bias.tgz" --exclude='*.npz' --exclude='*.pt' --exclude=tb \
  -C "$(dirname "$root")" "$(basename "$root")"
