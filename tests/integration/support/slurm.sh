# A real Slurm cluster (Debian's slurm-wlm 22.05 and munge) on the hosts of support/netns.sh, for
# the integration tests; sourced after netns.sh, used after netns_hosts:
#   hosta 198.51.100.1: slurmctld (and the client commands, through slurm_a)
#   hostb 198.51.100.2, hostc 198.51.100.3: a slurmd each, CPUs=2, partition "caliper" (default)
# Each daemon runs in its host's network namespace and in a UTS namespace of its own, so job steps
# on hostb see `hostname -s` = hostb and its address. One munged of the test's own, in namespace a
# (its socket is a file under WORK, reachable from every namespace). Config, state, spool and logs
# live in WORK/slurm; SLURM_CONF is exported. netns.sh's cleanup kills it all with the namespaces.
# No accounting (no slurmdbd): sacct does not work; `slurm_a scontrol show job ID` reports a
# finished job's state and exit code for MinJobAge (300 s) after it ended.
# Provides slurm_require, slurm_cluster, slurm_a, slurm_wait_job, slurm_kill_node, slurm_node_start.

SLURM_DIR=$WORK/slurm
export SLURM_CONF=$SLURM_DIR/slurm.conf
SLURM_MUNGE_SOCKET=$SLURM_DIR/munge/munge.socket

# skips (exit 77) when the Slurm daemons, client commands or munge are not installed
slurm_require() {
  local c
  for c in slurmctld slurmd sbatch srun squeue sinfo scancel scontrol munged; do
    command -v "$c" >/dev/null ||
      skip "no $c (launch/caliper deps slurm installs slurm-wlm and munge)"
  done
  command -v mungekey >/dev/null || command -v dd >/dev/null || skip "no mungekey to make a munge key"
}

# N CMD...: CMD on host N (a, b, c) as its daemons see it: hostname hostN (a UTS namespace of its
# own) and an /etc/hosts naming the three hosts (bind-mounted in a mount namespace of its own), so
# that `hostname -s` and `hostname -i` work in job steps
slurm_on() {
  local n=$1; shift
  # shellcheck disable=SC2016  # $1, $2 and $@ are sh's
  in_ns "$n" unshare --uts --mount sh -c 'mount --bind "$1" /etc/hosts && hostname "$2" &&
    shift 2 && exec "$@"' sh "$SLURM_DIR/hosts" "host$n" "$@"
}

# CMD...: a Slurm client command (sbatch, srun, squeue, sinfo, scancel, scontrol) on hosta
slurm_a() { slurm_on a env SLURM_CONF="$SLURM_CONF" "$@"; }

slurm_logs() {  # prints the end of every daemon's log (after a failure)
  local f
  for f in "$SLURM_DIR"/*.out; do  # stderr, which has the log too once the log file is open
    [ -s "${f%.out}.log" ] && f=${f%.out}.log
    echo "---- $f"; tail -n 40 "$f"
  done
  echo "---- $SLURM_DIR/munged.log"; tail -n 20 "$SLURM_DIR/munged.log"
}

# b|c: (re)starts that host's slurmd (hostname hostb/hostc) in the background
slurm_node_start() {
  slurm_on "$1" slurmd -D -N "host$1" -f "$SLURM_CONF" >>"$SLURM_DIR/slurmd-host$1.out" 2>&1 &
}

# writes the config, starts munged, slurmctld and both slurmds; returns when hostb and hostc are
# idle (exit 1 with the daemons' logs when they are not within 30 s)
slurm_cluster() {
  local d=$SLURM_DIR
  mkdir -p "$d/munge" "$d/state" "$d/spool-hostb" "$d/spool-hostc"
  # munge refuses a socket in a directory that not everybody may enter (WORK is 0700); --force
  # turns that into a warning. Everything here runs as root, so nobody else needs the socket.
  if command -v mungekey >/dev/null; then mungekey -c -k "$d/munge/munge.key"
  else dd if=/dev/urandom of="$d/munge/munge.key" bs=1024 count=1 status=none; fi
  chmod 600 "$d/munge/munge.key"
  printf '127.0.0.1 localhost\n198.51.100.1 hosta\n198.51.100.2 hostb\n198.51.100.3 hostc\n' >"$d/hosts"
  in_ns a munged -F --force --socket="$SLURM_MUNGE_SOCKET" --key-file="$d/munge/munge.key" \
    --pid-file="$d/munge/munged.pid" --seed-file="$d/munge/munged.seed" \
    --log-file="$d/munged.log" >>"$d/munged.log" 2>&1 &
  cat >"$SLURM_CONF" <<EOF
ClusterName=caliper
SlurmctldHost=hosta(198.51.100.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SLURM_MUNGE_SOCKET
StateSaveLocation=$d/state
SlurmctldPidFile=$d/slurmctld.pid
SlurmctldLogFile=$d/slurmctld.log
SlurmdSpoolDir=$d/spool-%n
SlurmdPidFile=$d/slurmd-%n.pid
SlurmdLogFile=$d/slurmd-%n.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
SlurmdParameters=config_overrides
ReturnToService=2
SlurmdTimeout=10
SlurmctldTimeout=10
MessageTimeout=5
KillWait=5
InactiveLimit=0
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=hostb NodeAddr=198.51.100.2 CPUs=2 State=UNKNOWN
NodeName=hostc NodeAddr=198.51.100.3 CPUs=2 State=UNKNOWN
PartitionName=caliper Nodes=hostb,hostc Default=YES MaxTime=INFINITE State=UP
EOF
  # cgroup/v1 spelt out: inside `ip netns exec` (a fresh /sys) the autodetection fails
  printf 'CgroupPlugin=cgroup/v1\nCgroupMountpoint=/sys/fs/cgroup\n' >"$d/cgroup.conf"
  for _ in $(seq 1 50); do [ -S "$SLURM_MUNGE_SOCKET" ] && break; sleep 0.1; done
  slurm_on a slurmctld -D -f "$SLURM_CONF" >>"$d/slurmctld.out" 2>&1 &
  slurm_node_start b
  slurm_node_start c
  for _ in $(seq 1 300); do
    [ "$(slurm_a sinfo -h -N -o '%N %t' 2>/dev/null | sort | tr '\n' ' ')" = "hostb idle hostc idle " ] &&
      return 0
    sleep 0.1
  done
  slurm_a sinfo -N 2>&1
  slurm_logs
  echo "FAIL: the Slurm cluster did not come up (hostb and hostc idle) within 30 s"
  exit 1
}

# JOBID TIMEOUT_S: waits until the job has left the queue (squeue lists a job while it is pending,
# running or completing; a finished one is no longer listed, a purged one is an "Invalid job id");
# 1 on timeout. A controller that does not answer is not taken for an empty queue.
slurm_wait_job() {
  local end=$((SECONDS + $2)) out
  while [ "$SECONDS" -lt "$end" ]; do
    if out=$(slurm_a squeue -h -j "$1" -o %i 2>&1); then
      [ -z "$out" ] && return 0
    else
      case $out in *"Invalid job id"*) return 0 ;; esac
    fi
    sleep 0.2
  done
  return 1
}

# b|c: a node crash: kills that host's slurmd and every process in its namespace (job steps too)
slurm_kill_node() {
  local p
  for p in $(ip netns pids "$TAG-$1" 2>/dev/null); do kill -KILL "$p" 2>/dev/null; done
}
