#!/bin/bash
# A one-node Slurm cluster on this machine, for testing the sweep job
# scripts (.ci/run uses it; so can a developer). Debian 12's Slurm 22.05, as
# root, no systemd: the daemons run in the background and are stopped by
# the PIDs recorded here.
#
#   scripts/slurm/cluster.sh install   apt-get the packages (daemons not started)
#   scripts/slurm/cluster.sh up        write slurm.conf, start slurmctld and slurmd,
#                                      wait until the node is idle
#   scripts/slurm/cluster.sh down      cancel what is left, stop the daemons
#
# Then: export SLURM_CONF=$ERRP_SLURM_DIR/etc/slurm.conf (default dir
# /tmp/errp-slurm) before sbatch, squeue, scancel.
case "${1:-}" in
  -h | --help) awk 'NR > 1 && /^#SBATCH/ { exit } NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
set -euo pipefail
D=${ERRP_SLURM_DIR:-/tmp/errp-slurm}
export SLURM_CONF=$D/etc/slurm.conf
say() { echo "[cluster $(date +%T)] $*" >&2; }

install() {
  command -v slurmctld >/dev/null && command -v sbatch >/dev/null && return 0
  # Keep apt from starting the services it installs.
  local policy=0
  if [ ! -e /usr/sbin/policy-rc.d ]; then
    printf '#!/bin/sh\nexit 101\n' > /usr/sbin/policy-rc.d
    chmod +x /usr/sbin/policy-rc.d
    policy=1
  fi
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    slurmctld slurmd slurm-client munge >/dev/null
  [ "$policy" = 1 ] && rm -f /usr/sbin/policy-rc.d
  say "installed $(slurmd -V)"
}

up() {
  mkdir -p "$D"/{etc,state,spool,log}
  local host node cpus mem plugins auth
  host=$(hostname -s)
  node=$(slurmd -C | head -1)
  cpus=$(sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' <<< "$node")
  mem=$(( $(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<< "$node") * 9 / 10 ))
  plugins=$(dirname "$(dpkg -L slurm-wlm-basic-plugins | grep -m1 '/auth_munge.so$')")
  if [ -e "$plugins/auth_none.so" ]; then
    auth=$'AuthType=auth/none\nCredType=cred/none'
  else
    mkdir -p "$D/munge" && chmod 700 "$D/munge"
    if [ ! -s /etc/munge/munge.key ]; then
      dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 status=none
      chmod 400 /etc/munge/munge.key
    fi
    munged -F --force --key-file=/etc/munge/munge.key --socket="$D/munge/socket" \
      --pid-file="$D/munge/pid" --seed-file="$D/munge/seed" > "$D/log/munged.log" 2>&1 &
    echo $! > "$D/munged.bgpid"
    for _ in $(seq 50); do [ -S "$D/munge/socket" ] && break; sleep 0.1; done
    auth=$'AuthType=auth/munge\nCredType=cred/munge\n'"AuthInfo=socket=$D/munge/socket"
  fi
  # Cores and memory as consumable resources (DefMemPerCPU), or every task
  # takes the whole node and an array runs one task at a time; no scheduler
  # delays; finished jobs leave the queue after 5 s, so `sbatch --wait`
  # polls every 2 s; a job whose dependency failed is cancelled, not left
  # pending forever.
  cat > "$SLURM_CONF" <<CONF
ClusterName=errp
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
$auth
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
DefMemPerCPU=$(( mem / cpus ))
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
DependencyParameters=kill_invalid_depend
ReturnToService=2
MailProg=/bin/true
MinJobAge=5
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/log/slurmctld.log
SlurmdLogFile=$D/log/slurmd.log
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
  slurmctld -D -f "$SLURM_CONF" > "$D/log/slurmctld.out" 2>&1 &
  echo $! > "$D/slurmctld.bgpid"
  for _ in $(seq 100); do scontrol ping > /dev/null 2>&1 && break; sleep 0.2; done
  slurmd -D -f "$SLURM_CONF" > "$D/log/slurmd.out" 2>&1 &
  echo $! > "$D/slurmd.bgpid"
  local state=""
  for _ in $(seq 120); do
    state=$(sinfo -h -n "$host" -o %T 2> /dev/null || true)
    if [ "$state" = idle ]; then
      say "node $host idle: $cpus CPUs, $mem MB (SLURM_CONF=$SLURM_CONF)"
      return 0
    fi
    sleep 0.5
  done
  say "the node never became idle (state '$state')"
  tail -n 20 "$D"/log/*.log >&2
  return 1
}

stop() { # stop NAME: TERM the PID recorded in NAME.bgpid, then KILL
  local f=$D/$1.bgpid pid
  [ -s "$f" ] || return 0
  pid=$(cat "$f")
  if kill -0 "$pid" 2> /dev/null; then
    kill "$pid"
    for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.2; done
    kill -0 "$pid" 2> /dev/null && kill -9 "$pid"
  fi
  rm -f "$f"
}

down() {
  if [ -s "$D/slurmctld.bgpid" ]; then
    squeue -h -o %A 2> /dev/null | xargs -r scancel 2> /dev/null || true
    sleep 1
  fi
  stop slurmd
  stop slurmctld
  # Job steps left behind carry our SLURM_CONF in their environment.
  local p
  for p in $(pgrep -x slurmstepd || true); do
    if tr '\0' '\n' < "/proc/$p/environ" 2> /dev/null | grep -qx "SLURM_CONF=$SLURM_CONF"; then
      kill -9 "$p" 2> /dev/null || true
    fi
  done
  stop munged
  say "stopped"
}

case "${1:-}" in
  install) install ;;
  up) up ;;
  down) down ;;
  *) echo "usage: $0 install|up|down" >&2; exit 2 ;;
esac
