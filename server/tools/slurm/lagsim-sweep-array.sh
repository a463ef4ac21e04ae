#!/bin/bash
# A lagsim-sweep on a Slurm cluster: one job array, one shard per array task.
#
#   sbatch --array=0-15 lagsim-sweep-array.sh OUTDIR -- --config S --controller 'C' \
#          --duration 10 --vary 'parameters.m1=uniform(0.4,0.6)' --runs 1000 --seed 1
#   lagsim-sweep merge OUTDIR/shard-*.csv -o sweep.csv     # once every task is done
#
# Task i of an array of N (Slurm's SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_MIN,
# SLURM_ARRAY_TASK_STEP and SLURM_ARRAY_TASK_COUNT; a stepped array --array=0-15:2 has
# the ids 0, 2, ..., 14) runs --shard K/N, K = (i - min) / step + 1, with
# -j SLURM_CPUS_PER_TASK workers and writes
# OUTDIR/shard-K-of-N.csv; the merge gives the CSV one machine would have written, bit for
# bit (run i's values come from --seed and i alone). Each shard carries the sweep's
# identity lines (--seed, the scene's SHA-256, the case, --vary, runs, K/N, ...): merge
# refuses a file of another sweep or another array left in OUTDIR, and names the shard
# of a task that failed or has not finished (missing shard K/N). OUTDIR must be on a file
# system the nodes share. LAGSIM_SWEEP names the program (default: lagsim-sweep on PATH).
#SBATCH --job-name=lagsim-sweep
#SBATCH --array=0-15
#SBATCH --cpus-per-task=2
#SBATCH --output=lagsim-sweep-%A_%a.out
set -euo pipefail
[ $# -ge 2 ] && [ "$2" = "--" ] || { echo "usage: $0 OUTDIR -- LAGSIM-SWEEP-OPTIONS..." >&2; exit 2; }
out=$1
shift 2
: "${SLURM_ARRAY_TASK_ID:?not an array task (sbatch --array)}"
: "${SLURM_ARRAY_TASK_COUNT:?not an array task (sbatch --array)}"
step=${SLURM_ARRAY_TASK_STEP:-1}
k=$(((SLURM_ARRAY_TASK_ID - ${SLURM_ARRAY_TASK_MIN:-0}) / step + 1))
n=$SLURM_ARRAY_TASK_COUNT
mkdir -p "$out"
exec "${LAGSIM_SWEEP:-lagsim-sweep}" "$@" --shard "$k/$n" -j "${SLURM_CPUS_PER_TASK:-1}" \
     --csv "$out/shard-$k-of-$n.csv" --force
