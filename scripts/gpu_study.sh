#!/usr/bin/env bash
# The recipe comparison of docs/study.md on a GPU machine (16 cores, one GPU) without Ray:
# 6 settings x 3 seeds of `simoun-train --preset cpu` on dm_control cartpole-swingup, run side
# by side as plain processes for at most STUDY_SECONDS each, then packed (logs and CSVs, no
# checkpoints) into $OUT/study.tgz for `simoun-report`.
# Usage (from the repo root, with simoun and its dmc extra installed):
#   STUDY_SECONDS=470 bash scripts/gpu_study.sh
set -u
seconds=${STUDY_SECONDS:-470}
steps=${STUDY_STEPS:-100000}
root=${STUDY_DIR:-/tmp/study}
out=${OUT:-/tmp/out}
mkdir -p "$root" "$out"

train() {  # variant seed flags...
  local variant=$1 seed=$2
  shift 2
  timeout "$seconds" python3 -m simoun_agent.run.train --preset cpu \
    --total-env-steps "$steps" --eval-every 10000 --eval-episodes 5 \
    --checkpoint-every 1000000 --video false --progress false --seed "$seed" \
    --run-dir "$root/$variant/s$seed" "$@" >"$root/$variant-s$seed.log" 2>&1
}

if command -v nvidia-smi >/dev/null; then  # GPU load over the study, for the notes
  nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv -l 30 \
    >"$root/gpu-utilization.csv" 2>&1 &
  monitor=$!
fi

for seed in 1 2 3; do
  train simoun "$seed" --agent.recipe simoun &
  train simoun_shift "$seed" --agent.recipe simoun --agent.augmentation shift &
  train simoun_shift_nstep3 "$seed" --agent.recipe simoun --agent.augmentation shift \
    --agent.n-step 3 &
  train drq "$seed" --agent.recipe drq &
  train curl "$seed" --agent.recipe curl &
  train sac "$seed" --agent.recipe sac &
done
wait $(jobs -p | grep -v "^${monitor:-none}$")
[ -n "${monitor:-}" ] && kill "$monitor"
tar czf "$out/study.tgz" --exclude='*.npz' --exclude='*.pt' --exclude=tb -C "$(dirname "$root")" \
  "$(basename "$root")"
