#!/usr/bin/env bash
# CTest `cluster` (label cluster): the workflow on a real one-node Slurm cluster started here, against the same
# workflow run locally. Installs slurm-wlm, munge and snakemake when missing (as root, as CI runs), starts munged,
# slurmctld and slurmd with their own config, keys, spool and state folders under WORK (no system file is
# touched), runs pipelines/workflow/config/ci.yaml (two scenes, two methods, 64x48: renders in two frame chunks,
# stateful filters as two chained jobs, compare in two shards merged) once with `snakemake --cores 2` and once
# through Slurm (pipelines/profiles/slurm), requires every output EXR to be pixel-identical and every metric of
# compare's JSON to be equal, and stops the daemons it started by their PIDs. It fails, with the reason, when a
# daemon cannot be started; it never skips.
#
# Usage: tests/cluster/check_cluster.sh SOURCE_DIR BUILD_DIR WORK_DIR
# Environment: TEMPORAL_CLUSTER_CONFIG=FILE runs another workflow config the same way (e.g. config/sweep.yaml with
# BUILD_DIR build/release, for the measurements of docs/pipelines.md).
set -euo pipefail
src="$1"; build="$2"; work="$3"
fail() { echo "cluster test: $*" >&2; exit 1; }
say() { echo "cluster test: $*" >&2; }

# --- packages ---------------------------------------------------------------------------------------------
missing=()
for p in slurm-wlm munge snakemake; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [[ ${#missing[@]} -gt 0 ]]; then
  [[ "$(id -u)" -eq 0 ]] || fail "needs ${missing[*]} (Debian packages) and is not root to install them"
  say "installing ${missing[*]}"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null ||
    fail "apt-get install ${missing[*]} failed"
fi
[[ "$(id -u)" -eq 0 ]] || fail "slurmd must run as root here (a one-node cluster without a slurm user)"

rm -rf "$work"
mkdir -p "$work"/{munge/key,munge/run,state,spool,log}
work="$(cd "$work" && pwd)"
pids=()
stop() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  sleep 1
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
}
trap stop EXIT

# --- munge: its own key and socket ---------------------------------------------------------------------------
mungekey --create --keyfile "$work/munge/key/munge.key" >/dev/null 2>&1 || fail "mungekey --create failed"
chown -R munge:munge "$work/munge"
chmod 700 "$work/munge/key"
chmod 755 "$work" "$work/munge" "$work/munge/run"
sock="$work/munge/run/munge.socket"
su -s /bin/sh munge -c "/usr/sbin/munged --socket=$sock --key-file=$work/munge/key/munge.key \
  --pid-file=$work/munge/run/munged.pid --log-file=$work/munge/run/munged.log --seed-file=$work/munge/run/munged.seed" ||
  fail "munged did not start: $(cat "$work/munge/run/munged.log" 2>/dev/null | tail -3)"
pids+=("$(cat "$work/munge/run/munged.pid")")
munge -S "$sock" -n | unmunge -S "$sock" >/dev/null || fail "munge does not answer on $sock"

# --- slurm: one node, this machine ------------------------------------------------------------------------------
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
host="$(hostname -s)"
mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 8 / 10 ))
export SLURM_CONF="$work/slurm.conf"
cat > "$SLURM_CONF" <<CONF
ClusterName=temporaltest
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$sock
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
SwitchType=switch/none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
NodeName=$host CPUs=$(nproc) RealMemory=$mem State=UNKNOWN
PartitionName=temporal Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -i -f "$SLURM_CONF" || fail "slurmctld did not start: $(tail -3 "$work/log/slurmctld.log" 2>/dev/null)"
for _ in $(seq 50); do [[ -s "$work/slurmctld.pid" ]] && break; sleep 0.1; done
pids+=("$(cat "$work/slurmctld.pid")")
slurmd -f "$SLURM_CONF" || fail "slurmd did not start: $(tail -3 "$work/log/slurmd.log" 2>/dev/null)"
for _ in $(seq 50); do [[ -s "$work/slurmd.pid" ]] && break; sleep 0.1; done
pids+=("$(cat "$work/slurmd.pid")")
up=0
for _ in $(seq 60); do
  if sinfo -h -o '%t' 2>/dev/null | grep -q idle; then up=1; break; fi
  sleep 0.5
done
[[ $up == 1 ]] || fail "the node never became idle: $(sinfo 2>&1 | tail -2); $(tail -3 "$work/log/slurmd.log")"
say "one-node cluster up on $host ($(nproc) CPUs)"

# --- the workflow, locally and through Slurm ---------------------------------------------------------------------
flow="$src/pipelines/workflow/Snakefile"
cfg="${TEMPORAL_CLUSTER_CONFIG:-$src/pipelines/workflow/config/ci.yaml}"  # another config: docs/pipelines.md
t0=$(date +%s)
snakemake -s "$flow" --configfile "$cfg" --config "build=$build" "out=$work/local" --directory "$work/local-wd" \
  --cores 2 -q > "$work/log/local.log" 2>&1 || fail "local run failed: $(tail -20 "$work/log/local.log")"
t1=$(date +%s)
snakemake -s "$flow" --configfile "$cfg" --config "build=$build" "out=$work/slurm" --directory "$work/slurm-wd" \
  --profile "$src/pipelines/profiles/slurm" --default-resources partition=temporal mem_mb=500 --jobs 4 \
  --latency-wait 10 > "$work/log/slurm.log" 2>&1 || fail "Slurm run failed: $(tail -20 "$work/log/slurm.log")"
t2=$(date +%s)
jobs=$(find "$work/slurm-wd/logs/slurm" -name '*.out' 2>/dev/null | wc -l)
[[ $jobs -ge 10 ]] || fail "only $jobs jobs went through Slurm (expected every rule but 'all')"
say "local run $((t1 - t0)) s, Slurm run $((t2 - t1)) s ($jobs Slurm jobs)"

# --- identical outputs -------------------------------------------------------------------------------------------
n=0
while IFS= read -r f; do
  rel="${f#"$work/local/"}"
  [[ -f "$work/slurm/$rel" ]] || fail "$rel is missing from the Slurm run"
  idiff -a -fail 0 -warn 0 "$f" "$work/slurm/$rel" >/dev/null 2>&1 || fail "$rel differs between the local and the Slurm run"
  n=$((n + 1))
done < <(find "$work/local" -name '*.exr' | sort)
[[ $n -gt 40 ]] || fail "only $n EXR files were produced"
python3 - "$work/local" "$work/slurm" <<'PY' || fail "compare's metrics differ between the local and the Slurm run"
import json, pathlib, sys
a, b = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
def metrics(p):
    j = json.loads(p.read_text())
    # Times differ between runs, and so does what is derived from them (the speed chart's Pareto flags).
    timed = ("path", "pareto")
    return [{k: v for k, v in s.items() if not k.endswith("_ms") and k not in timed} for s in j["sequences"]], j["paired"]
files = sorted(a.rglob("compare.json"))
assert files, "no compare.json"
for f in files:
    assert metrics(f) == metrics(b / f.relative_to(a)), f
print(f"{len(files)} compare.json identical")
PY
say "$n EXR files and every compare.json identical between the local and the Slurm run"
