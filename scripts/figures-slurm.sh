#!/usr/bin/env bash
# scripts/figures-slurm.sh — one line of a job file written by
# `scripts/figures.sh --export-jobs FILE`, as one task of a Slurm job array:
#
#   scripts/figures.sh --export-jobs jobs.txt --runs runs      # on the login node, in the checkout
#   sbatch --array=1-$(wc -l < jobs.txt)%100 --output=runs/slurm-%A_%a.out scripts/figures-slurm.sh jobs.txt
#   scripts/figures.sh --merge runs                              # when the array is done
#
# Task N runs line N (+ FIG_LINE_OFFSET, for files longer than the cluster's
# MaxArraySize: submit the lines in blocks, e.g. --export=ALL,FIG_LINE_OFFSET=1000
# --array=1-1000 for lines 1001-2000). The lines run from the top of the
# checkout (sbatch's working directory, SLURM_SUBMIT_DIR), which every node
# sees at the same path and has built (`make`); each run writes only its own
# folder under the runs' directory, so the tasks share nothing else. A run
# is a simulator and a few daemons in lockstep, about 1 s of two cores.
# The default output file below is relative to the job's working directory,
# the checkout's top: give --output (above) to keep it beside the runs.
# Run for real on a one-node Slurm 22.05 by tests/long/figures_slurm.sh.
#SBATCH --job-name=undulate-figures
#SBATCH --cpus-per-task=2
#SBATCH --time=00:10:00
#SBATCH --output=slurm-%A_%a.out
set -u
jobs=${1:-}
# named, not $0: under Slurm $0 is slurmd's copy of this script in its spool
# folder (.../job00006/slurm_script), which says nothing to the user
[ -n "$jobs" ] && [ -f "$jobs" ] || { echo "figures-slurm: usage: sbatch --array=1-N scripts/figures-slurm.sh JOBFILE" >&2; exit 2; }
task=${SLURM_ARRAY_TASK_ID:-}
[[ "$task" =~ ^[0-9]+$ ]] || { echo "figures-slurm: SLURM_ARRAY_TASK_ID is not set: submit with sbatch --array" >&2; exit 2; }
offset=${FIG_LINE_OFFSET:-0}
[[ "$offset" =~ ^[0-9]+$ ]] || { echo "figures-slurm: FIG_LINE_OFFSET='$offset' is not a whole number" >&2; exit 2; }
cd "${SLURM_SUBMIT_DIR:-.}" || exit 2
line=$(sed -n "$((task + offset))p" "$jobs")
[ -n "$line" ] || { echo "figures-slurm: $jobs has no line $((task + offset))" >&2; exit 2; }
case "$line" in
"scripts/figures.sh run "*) ;;
*) echo "figures-slurm: line $((task + offset)) of $jobs is not a figures run: $line" >&2; exit 2 ;;
esac
# the line was written by figures.sh (%q-quoted paths, checked words)
eval "$line"
