#!/usr/bin/env bash
# A stand-in for Slurm's sbatch, for tests/slurm_sweep_test.cpp (named `sbatch` on the PATH of
# tools/slurm/submit_sweep.sh). It runs each job at once on this machine and returns when it has
# finished: --array=A-B starts tasks A … B as parallel processes with SLURM_ARRAY_JOB_ID,
# SLURM_ARRAY_TASK_ID, _COUNT, _MIN and _MAX set, as Slurm does; --dependency=afterok:ID runs the
# job only if every task of job ID succeeded (Slurm would never start it otherwise). --parsable
# prints the job id; --output=FILE (with %A, %a, %j) takes each task's stdout and stderr. Every
# job's outcome goes to $FAKE_SBATCH_STATE/<id> ("ok", "failed" or "never ran").
set -euo pipefail
state=${FAKE_SBATCH_STATE:?set FAKE_SBATCH_STATE to a directory}

array="" dependency="" output="" parsable=0
while [[ $# -gt 0 && $1 == --* ]]; do
  case $1 in
    --array=*) array=${1#--array=} ;;
    --dependency=*) dependency=${1#--dependency=} ;;
    --output=*) output=${1#--output=} ;;
    --parsable) parsable=1 ;;
    *)
      echo "fake sbatch: unsupported option $1" >&2
      exit 2
      ;;
  esac
  shift
done
script=$1
shift

id=$((1000 + $(find "$state" -maxdepth 1 -type f | wc -l)))
if [[ -n $dependency ]]; then
  for needed in $(tr ':' ' ' <<<"${dependency#afterok:}"); do
    if [[ $(cat "$state/$needed" 2>/dev/null) != ok ]]; then
      echo "never ran" >"$state/$id"
      ((parsable)) && echo "$id"
      exit 0
    fi
  done
fi

first=0 last=0
if [[ -n $array ]]; then
  first=${array%-*} last=${array#*-}
fi
pids=()
for ((task = first; task <= last; ++task)); do
  log=${output:-$state/slurm-%j.out}
  log=${log//%A/$id} log=${log//%a/$task} log=${log//%j/$id.$task}
  if [[ -n $array ]]; then
    SLURM_ARRAY_JOB_ID=$id SLURM_ARRAY_TASK_ID=$task SLURM_ARRAY_TASK_COUNT=$((last - first + 1)) \
      SLURM_ARRAY_TASK_MIN=$first SLURM_ARRAY_TASK_MAX=$last SLURM_JOB_ID=$id \
      bash "$script" "$@" >"$log" 2>&1 &
  else
    SLURM_JOB_ID=$id bash "$script" "$@" >"$log" 2>&1 &
  fi
  pids+=($!)
done
outcome=ok
for pid in "${pids[@]}"; do wait "$pid" || outcome=failed; done
echo "$outcome" >"$state/$id"
((parsable)) && echo "$id"
exit 0
