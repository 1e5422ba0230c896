#!/usr/bin/env bash
# Smoke test of the SLURM profile on a real one-node SLURM cluster, brought up under a temporary folder.
#
#   bash tests/cluster/slurm_smoke.sh            (as root, on Debian or Ubuntu; installs what is missing)
#
# 1. Runs the README's cluster command on a small target (the device tests and one trial of S01) and checks
#    that every SLURM job is COMPLETED in sacct and that the files equal a local `snakemake -j2` run's, byte
#    for byte (logs and benchmark timings aside).
# 2. Cancels a running job: the run must end with SLURM's CANCELLED state named, well within 5 minutes,
#    and the same command must then complete the work, again equal to the local run.
# 3. Bad input, each with a clear message and nothing half-written: a robot log that cannot be read (one
#    submission, no retry, the message in the rule's own log), a job killed by SLURM for memory, a partition
#    that does not exist, sbatch missing from PATH.
# Exits 0 with "skipped: ..." where it cannot run (not root, no apt-get, packages not installable).
# KEEP=1 keeps the temporary folder (daemons' logs, both runs) for a look afterwards.
set -euo pipefail

REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
TARGETS=(results/device/summary.tsv results/strides/S01/pert050-1.strides.tsv)
PROFILE=workflow/profiles/slurm
RUN_LIMIT_S=900    # no cluster run of this test may take longer (a hang fails the test, it never blocks CI)
CANCEL_LIMIT_S=300 # a cancelled job must end the run within this time

skip() { echo "slurm smoke test skipped: $*"; exit 0; }
fail() { echo "slurm smoke test FAILED: $*" >&2; exit 1; }
step() { echo "--- $(date +%T) $*"; }

[ "$(id -u)" = 0 ] || skip "needs root (it starts munged, mariadbd, slurmdbd, slurmctld and slurmd)"
command -v apt-get >/dev/null || skip "needs apt-get for Debian's slurm-wlm, slurmdbd, munge and mariadb-server"
missing=()
for pair in slurmctld:slurm-wlm slurmdbd:slurmdbd munged:munge mariadbd:mariadb-server; do
    command -v "${pair%%:*}" >/dev/null || missing+=("${pair#*:}")
done
if ((${#missing[@]})); then
    step "installing ${missing[*]}"
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        "${missing[@]}" >/dev/null; } || skip "could not install ${missing[*]} with apt-get"
fi
python -c "import snakemake_executor_plugin_slurm" 2>/dev/null ||
    fail "snakemake-executor-plugin-slurm is not installed (pip install -r requirements.txt)"

WORK=$(mktemp -d /tmp/loper-slurm-smoke.XXXXXX)
# shellcheck source=tests/cluster/slurm_cluster.sh
source "$REPO/tests/cluster/slurm_cluster.sh"
cleanup() {
    local rc=$?
    cluster_down
    if [ "${KEEP:-0}" = 1 ] || [ $rc != 0 ]; then echo "kept $WORK"; else rm -rf "$WORK"; fi
}
trap cleanup EXIT

copy_repo() {  # the repository's files (tracked and new, not ignored, no results) into a fresh folder
    mkdir -p "$1"
    (cd "$REPO" && git ls-files -co --exclude-standard | grep -v -e '^results/' -e '^data/raw/' |
        tar -cf - -T -) | tar -xf - -C "$1"
}

results_digest() {  # every result and generated raw file with its checksum; logs and timings aside
    (cd "$1" && find results data/raw -type f ! -path 'results/logs/*' ! -path 'results/benchmarks/*' \
        -print0 | sort -z | xargs -0 sha256sum)
}

no_staged_files() {  # the atomic writer stages beside the target as .{name}.*.partial: none may remain
    local left
    left=$(cd "$1" && find results data -name '.*.partial' 2>/dev/null | head -5)
    [ -z "$left" ] || fail "half-written files left behind: $left"
}

cluster_run() {  # cluster_run DIR LOG [args]: the README's cluster command, bounded in time; prints its status
    local dir=$1 log=$2
    shift 2
    (cd "$dir" && timeout --signal=INT --kill-after=60 "$RUN_LIMIT_S" \
        snakemake --workflow-profile "$PROFILE" "$@" >"$log" 2>&1) && echo 0 || echo $?
}

jobs_not_completed() {  # SLURM jobs of the test cluster since job id $1 whose state is not COMPLETED
    sacct -X -n -P -o JobID,State | awk -F'|' -v from="$1" '$1 >= from && $2 != "COMPLETED"'
}

no_trials_of() {  # no C3D or robot log of subject $2 in the copy $1 (the synthetic lab's outputs)
    local left
    left=$(cd "$1" && find "data/raw/$2" \( -name '*.c3d' -o -name '*.loper.tsv' \) 2>/dev/null | head -3)
    [ -z "$left" ] || fail "files of a job that could not run were left behind: $left"
}

last_job_id() { sacct -X -n -P -o JobID | sort -n | tail -1 | grep . || echo 0; }

step "bringing up a one-node SLURM cluster in $WORK/cluster"
cluster_up "$WORK/cluster" >/dev/null || fail "the cluster did not come up (logs in $WORK/cluster)"
sinfo

step "local run: snakemake -j2 ${TARGETS[*]}"
copy_repo "$WORK/local"
(cd "$WORK/local" && snakemake -j2 "${TARGETS[@]}" >"$WORK/local.log" 2>&1) || fail "local run failed: $WORK/local.log"
results_digest "$WORK/local" >"$WORK/local.sha256"

step "cluster run: snakemake --workflow-profile $PROFILE ${TARGETS[*]}"
copy_repo "$WORK/slurm"
first=$(($(last_job_id) + 1))
start=$SECONDS
rc=$(cluster_run "$WORK/slurm" "$WORK/slurm.log" "${TARGETS[@]}")
[ "$rc" = 0 ] || fail "cluster run ended with status $rc: $WORK/slurm.log"
n_jobs=$(sacct -X -n -P -o JobID | awk -v from="$first" '$1 >= from' | wc -l)
[ "$n_jobs" -gt 0 ] || fail "no SLURM job was submitted"
bad=$(jobs_not_completed "$first")
[ -z "$bad" ] || fail "SLURM jobs not COMPLETED: $bad"
results_digest "$WORK/slurm" | diff "$WORK/local.sha256" - >"$WORK/diff.txt" ||
    fail "cluster outputs differ from the local run's: $WORK/diff.txt"
echo "ok: $n_jobs SLURM jobs COMPLETED in $((SECONDS - start)) s; $(wc -l <"$WORK/local.sha256") files equal the local run's"

step "cancel: scancel a running job, the run must end with a clear message"
first=$(($(last_job_id) + 1))
cluster_run "$WORK/slurm" "$WORK/cancel.log" "${TARGETS[@]}" --forcerun ik >"$WORK/cancel.rc" &
runner=$!
for _ in $(seq 240); do
    victim=$(squeue -h -t RUNNING -o %i | head -1)
    [ -n "$victim" ] && break
    sleep 0.5
done
[ -n "${victim:-}" ] || fail "no job started running within 120 s: $WORK/cancel.log"
scancel "$victim"
start=$SECONDS
while kill -0 "$runner" 2>/dev/null; do
    ((SECONDS - start < CANCEL_LIMIT_S)) || fail "the run still waits ${CANCEL_LIMIT_S} s after scancel: $WORK/cancel.log"
    sleep 1
done
[ "$(cat "$WORK/cancel.rc")" != 0 ] || fail "the run succeeded although its job $victim was cancelled"
# the console names the job and says why it ended (the run's onerror handler reads SLURM's output of the job)
grep -q "SLURM job $victim (.*): cancelled (scancel)" "$WORK/cancel.log" ||
    fail "the run's output does not say that job $victim was cancelled: $WORK/cancel.log"
echo "ok: job $victim cancelled, the run ended $((SECONDS - start)) s later naming it"
no_staged_files "$WORK/slurm"
rc=$(cluster_run "$WORK/slurm" "$WORK/resume.log" "${TARGETS[@]}")
[ "$rc" = 0 ] || fail "the rerun after the cancel ended with status $rc: $WORK/resume.log"
results_digest "$WORK/slurm" | diff "$WORK/local.sha256" - >"$WORK/diff.txt" ||
    fail "after the rerun, outputs differ from the local run's: $WORK/diff.txt"
echo "ok: the rerun completed, outputs equal the local run's"

step "bad input: an unreadable robot log fails once, its message in the rule's log"
# a lab's own log: S01 marked 'recorded' (a synthetic subject's folder holds only what the synthetic lab wrote,
# and a run stops before any job on a file it did not write)
log_file=data/raw/S01/pert050-1.loper.tsv
cp "$WORK/slurm/$log_file" "$WORK/robot_log.keep"
cp "$WORK/slurm/config/subjects.tsv" "$WORK/subjects.keep"
sed -i 's/^S01\tsynthetic\t/S01\trecorded\t/' "$WORK/slurm/config/subjects.tsv"
grep -q "^S01	recorded	" "$WORK/slurm/config/subjects.tsv" || fail "could not mark S01 recorded in config/subjects.tsv"
# first with its log intact: a recorded subject's jobs watch their raw files' content, so they run once more
rc=$(cluster_run "$WORK/slurm" "$WORK/recorded.log" results/strides/S01/pert050-1.strides.tsv)
[ "$rc" = 0 ] || fail "the run with S01 marked recorded ended with status $rc: $WORK/recorded.log"
printf 'time_s\tforce_n\nnot-a-number\t1\n' >"$WORK/slurm/$log_file"
rc=$(cluster_run "$WORK/slurm" "$WORK/badinput.log" results/strides/S01/pert050-1.strides.tsv)
[ "$rc" != 0 ] || fail "a run on an unreadable robot log succeeded: $WORK/badinput.log"
n_submitted=$(grep -c "has been submitted with SLURM jobid" "$WORK/badinput.log" || true)
[ "$n_submitted" = 1 ] || fail "the failing job was submitted $n_submitted times, expected once: $WORK/badinput.log"
rule_log=$WORK/slurm/results/logs/events_loadcell/S01/pert050-1.log
grep -q "$log_file" "$rule_log" || fail "the rule's log $rule_log does not name the bad file $log_file"
for out in results/events/S01/pert050-1.events.tsv results/loadcell/S01/pert050-1.force.tsv; do
    [ ! -e "$WORK/slurm/$out" ] || fail "$out of the failed job was left behind"
done
no_staged_files "$WORK/slurm"
cp "$WORK/robot_log.keep" "$WORK/slurm/$log_file"
cp "$WORK/subjects.keep" "$WORK/slurm/config/subjects.tsv"
echo "ok: one submission; the rule's log says: $(grep -m1 -o "LoperInputError.*" "$rule_log" | cut -c1-160)"

step "bad input: a job killed by SLURM for memory"
first=$(($(last_job_id) + 1))
rc=$(cluster_run "$WORK/slurm" "$WORK/memory.log" data/raw/S02/static.c3d --set-resources synthetic_lab:mem_mb=60)
[ "$rc" != 0 ] || fail "synthetic_lab with 60 MB succeeded: $WORK/memory.log"
grep -q "SLURM job [0-9]* (rule_synthetic_lab/S02): killed by SLURM for exceeding its memory" "$WORK/memory.log" ||
    fail "the run does not say the job was killed for memory: $WORK/memory.log"
no_trials_of "$WORK/slurm" S02
no_staged_files "$WORK/slurm"
echo "ok: $(grep -m1 -o "SLURM job [0-9]* (rule_synthetic_lab/S02): killed[^(]*" "$WORK/memory.log"); no trial of S02 written"

step "bad input: a partition that does not exist"
mkdir -p "$WORK/badprofile"
sed 's/slurm_partition: "standard"/slurm_partition: "nosuch"/' "$REPO/$PROFILE/config.yaml" >"$WORK/badprofile/config.yaml"
first=$(($(last_job_id) + 1))
rc=$( (cd "$WORK/slurm" && timeout 300 snakemake --workflow-profile "$WORK/badprofile" data/raw/S02/static.c3d \
    >"$WORK/partition.log" 2>&1) && echo 0 || echo $?)
[ "$rc" != 0 ] || fail "a run on partition 'nosuch' succeeded"
grep -q "slurm_partition 'nosuch' is not a partition of this cluster (sinfo lists: standard)" "$WORK/partition.log" ||
    fail "no clear message for the unknown partition: $WORK/partition.log"
[ "$(last_job_id)" -lt "$first" ] || fail "a job was submitted to the unknown partition"
no_trials_of "$WORK/slurm" S02
echo "ok: $(grep -m1 -o "cannot submit to SLURM.*" "$WORK/partition.log" | cut -c1-160)"

step "bad input: sbatch missing from PATH"
mkdir -p "$WORK/nosbatch"
for dir in $(echo "$PATH" | tr ':' ' '); do
    for f in "$dir"/*; do
        name=$(basename "$f")
        [ "$name" = sbatch ] || [ -e "$WORK/nosbatch/$name" ] || ln -s "$f" "$WORK/nosbatch/$name" 2>/dev/null || true
    done
done
rc=$( (cd "$WORK/slurm" && PATH=$WORK/nosbatch timeout 300 snakemake --workflow-profile "$PROFILE" \
    data/raw/S02/static.c3d >"$WORK/nosbatch.log" 2>&1) && echo 0 || echo $?)
[ "$rc" != 0 ] || fail "a run without sbatch succeeded"
grep -q "sbatch, which is not on PATH" "$WORK/nosbatch.log" || fail "no clear message without sbatch: $WORK/nosbatch.log"
no_trials_of "$WORK/slurm" S02
echo "ok: $(grep -m1 -o "cannot submit to SLURM.*" "$WORK/nosbatch.log" | cut -c1-120)"

step "slurm smoke test passed"
