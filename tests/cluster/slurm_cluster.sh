# A one-node SLURM cluster (with slurmdbd accounting) under a temporary folder, for the smoke test.
# Source this file, then call `cluster_up DIR` and `cluster_down`; every daemon is started here in the
# foreground of a background job, its PID recorded, and stopped by that PID only.
# Needs root and Debian's slurm-wlm, slurmdbd, munge and mariadb-server packages.

CLUSTER_PIDS=()

_free_port() {
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

_wait_for() {  # _wait_for SECONDS DESCRIPTION COMMAND...
    local limit=$1 what=$2
    shift 2
    for _ in $(seq "$((limit * 4))"); do
        if "$@" >/dev/null 2>&1; then return 0; fi
        sleep 0.25
    done
    echo "slurm cluster: $what did not come up within ${limit} s; logs in $CLUSTER_DIR" >&2
    return 1
}

_start() {  # _start NAME COMMAND...: run in the background, log to DIR/NAME.log, remember the PID
    local name=$1
    shift
    "$@" >"$CLUSTER_DIR/$name.log" 2>&1 &
    CLUSTER_PIDS+=("$!")
}

cluster_up() {
    CLUSTER_DIR=$1
    local host cpus mem_mb db_port ctld_port d_port dbd_port
    host=$(hostname -s)
    cpus=$(nproc)
    mem_mb=$(($(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 1024))
    db_port=$(_free_port); ctld_port=$(_free_port); d_port=$(_free_port); dbd_port=$(_free_port)
    mkdir -p "$CLUSTER_DIR"/{munge,db,state,spool}
    chmod 700 "$CLUSTER_DIR/munge"

    mungekey --create --keyfile="$CLUSTER_DIR/munge/munge.key" --force
    _start munged munged --foreground --force --key-file="$CLUSTER_DIR/munge/munge.key" \
        --socket="$CLUSTER_DIR/munge/munge.socket" --pid-file="$CLUSTER_DIR/munge/munged.pid" \
        --log-file="$CLUSTER_DIR/munge/munged.log" --seed-file="$CLUSTER_DIR/munge/munged.seed"
    _wait_for 20 munged test -S "$CLUSTER_DIR/munge/munge.socket" || return 1

    mariadb-install-db --datadir="$CLUSTER_DIR/db" --user=root --auth-root-authentication-method=normal \
        >"$CLUSTER_DIR/mariadb-install.log" 2>&1 || { echo "slurm cluster: mariadb-install-db failed" >&2; return 1; }
    _start mariadbd mariadbd --no-defaults --datadir="$CLUSTER_DIR/db" --socket="$CLUSTER_DIR/mysql.sock" \
        --port="$db_port" --bind-address=127.0.0.1 --user=root --pid-file="$CLUSTER_DIR/mariadbd.pid" \
        --skip-log-bin --innodb-buffer-pool-size=64M
    _wait_for 60 mariadbd mariadb --no-defaults --socket="$CLUSTER_DIR/mysql.sock" -uroot -e 'select 1' || return 1
    mariadb --no-defaults --socket="$CLUSTER_DIR/mysql.sock" -uroot -e \
        "create user 'slurm'@'127.0.0.1' identified by 'smoke'; grant all on slurm_acct_db.* to 'slurm'@'127.0.0.1';"

    cat >"$CLUSTER_DIR/slurmdbd.conf" <<EOF
AuthType=auth/munge
AuthInfo=socket=$CLUSTER_DIR/munge/munge.socket
DbdHost=localhost
DbdAddr=127.0.0.1
DbdPort=$dbd_port
SlurmUser=root
PidFile=$CLUSTER_DIR/slurmdbd.pid
LogFile=$CLUSTER_DIR/slurmdbd.daemon.log
StorageType=accounting_storage/mysql
StorageHost=127.0.0.1
StoragePort=$db_port
StorageUser=slurm
StoragePass=smoke
StorageLoc=slurm_acct_db
EOF
    chmod 600 "$CLUSTER_DIR/slurmdbd.conf"

    cat >"$CLUSTER_DIR/slurm.conf" <<EOF
ClusterName=smoke
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$CLUSTER_DIR/munge/munge.socket
StateSaveLocation=$CLUSTER_DIR/state
SlurmdSpoolDir=$CLUSTER_DIR/spool
SlurmctldPidFile=$CLUSTER_DIR/slurmctld.pid
SlurmdPidFile=$CLUSTER_DIR/slurmd.pid
SlurmctldLogFile=$CLUSTER_DIR/slurmctld.daemon.log
SlurmdLogFile=$CLUSTER_DIR/slurmd.daemon.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
SchedulerParameters=sched_min_interval=100000
MinJobAge=300
ReturnToService=2
JobAcctGatherType=jobacct_gather/linux
JobAcctGatherFrequency=task=1
JobAcctGatherParams=OverMemoryKill
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=127.0.0.1
AccountingStoragePort=$dbd_port
AccountingStoragePass=$CLUSTER_DIR/munge/munge.socket
MailProg=/bin/true
MpiDefault=none
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=standard Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF=$CLUSTER_DIR/slurm.conf  # slurmdbd reads slurmdbd.conf from the same folder
    # A real cluster keeps slurm.conf in /etc/slurm; this one lives here, and the executor's job step drops
    # every SLURM_* variable before its nested srun: a wrapper first on PATH hands srun the config.
    mkdir -p "$CLUSTER_DIR/bin"
    printf '#!/bin/sh\nSLURM_CONF=%s exec %s "$@"\n' "$SLURM_CONF" "$(command -v srun)" >"$CLUSTER_DIR/bin/srun"
    chmod +x "$CLUSTER_DIR/bin/srun"
    export PATH=$CLUSTER_DIR/bin:$PATH

    _start slurmdbd slurmdbd -D
    _wait_for 60 slurmdbd bash -c "echo > /dev/tcp/127.0.0.1/$dbd_port" || return 1
    sacctmgr -i add cluster smoke >"$CLUSTER_DIR/sacctmgr.log" 2>&1
    _start slurmctld slurmctld -D -c -f "$CLUSTER_DIR/slurm.conf"
    _wait_for 60 slurmctld scontrol ping || return 1
    _start slurmd slurmd -D -f "$CLUSTER_DIR/slurm.conf" -N "$host"
    _wait_for 60 "the node" bash -c "sinfo -h -o %t | grep -Eq '^(idle|mix|alloc)'" || return 1
    echo "slurm cluster: up in $CLUSTER_DIR (SLURM_CONF=$SLURM_CONF, PIDs ${CLUSTER_PIDS[*]})"
}

cluster_down() {
    local i
    for ((i = ${#CLUSTER_PIDS[@]} - 1; i >= 0; i--)); do  # in reverse order of starting
        kill "${CLUSTER_PIDS[$i]}" 2>/dev/null || true
        for _ in $(seq 40); do kill -0 "${CLUSTER_PIDS[$i]}" 2>/dev/null || break; sleep 0.25; done
        kill -9 "${CLUSTER_PIDS[$i]}" 2>/dev/null || true
    done
    CLUSTER_PIDS=()
}
