#!/usr/bin/env bash
# Runs a chorus sweep on a Slurm cluster (docs/cli.md, "Sweeps on a Slurm cluster"):
#   tools/slurm/submit_sweep.sh [--dry-run] N OUT SCENE... [chorus sweep flags]
# submits a job array of N tasks, task I running shard I/N of the sweep into OUT/shards/I
# (sweep.sbatch), and a merge job (merge.sbatch) that starts once every task has succeeded
# (--dependency=afterok) and writes OUT/results.csv and OUT/report.html. Logs: OUT/logs/.
# --dry-run submits nothing and prints the two sbatch commands and the chorus command of every
# job (with --threads only where SLURM_CPUS_PER_TASK is set, as it is inside the jobs). Environment: CHORUS, the chorus binary the jobs run (default: chorus on PATH, else this
# checkout's build/chorus); Slurm's own SBATCH_PARTITION, SBATCH_TIMELIMIT, SBATCH_ACCOUNT, …
# apply to both jobs. OUT, scenes and references must be on a file system the nodes share.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)

dry_run=0
if [[ ${1:-} == --dry-run ]]; then
  dry_run=1
  shift
fi
if [[ $# -lt 3 || ! $1 =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: tools/slurm/submit_sweep.sh [--dry-run] N OUT SCENE... [chorus sweep flags]" >&2
  exit 2
fi
shards=$1 out=$2
shift 2

chorus=${CHORUS:-$(command -v chorus || echo "$here/../../build/chorus")}
if [[ ! -x $chorus ]]; then
  echo "submit_sweep.sh: $chorus: no chorus binary there (set CHORUS)" >&2
  exit 2
fi
# The jobs may start in another directory than this script's caller sees: absolute paths.
CHORUS=$(realpath "$chorus")
export CHORUS

array=(sbatch --parsable --array="0-$((shards - 1))" --output="$out/logs/shard-%a.out"
  "$here/sweep.sbatch" "$out" "$@")
merge=(sbatch --parsable --output="$out/logs/merge.out" "$here/merge.sbatch" "$out" "$shards")

if ((dry_run)); then
  printf '%q' "${array[0]}"
  printf ' %q' "${array[@]:1}"
  printf '\n'
  for ((i = 0; i < shards; ++i)); do
    printf '  task %d: ' "$i"
    SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=$shards CHORUS_DRY_RUN=1 \
      bash "$here/sweep.sbatch" "$out" "$@"
  done
  printf '%q' "${merge[0]}"
  printf ' %q' "${merge[1]}" --dependency=afterok:ARRAY_JOB_ID "${merge[@]:2}"
  printf '\n  merge: '
  CHORUS_DRY_RUN=1 bash "$here/merge.sbatch" "$out" "$shards"
  exit 0
fi

mkdir -p "$out/logs"  # Slurm does not create the directories of --output
array_job=$("${array[@]}")
array_job=${array_job%%;*}  # --parsable prints "id" or "id;cluster"
merge_job=$("${merge[@]:0:2}" --dependency=afterok:"$array_job" "${merge[@]:2}")
echo "submitted shards: job array $array_job ($shards tasks); merge: job ${merge_job%%;*}"
echo "results: $out/results.csv and $out/report.html once job ${merge_job%%;*} has finished"
