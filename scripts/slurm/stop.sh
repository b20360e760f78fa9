#!/bin/bash
# Stops the test cluster that scripts/slurm/start.sh started in STATE_DIR (argument, else
# $EMAKI_SLURM_DIR, else build/slurm): cancels its jobs, ends slurmd, slurmctld, any job
# processes left and munged (by their pid files; TERM, then KILL after 10 s) and waits for them
# to exit. Nothing running (or called twice) is fine. Logs stay in STATE_DIR/log.
set -u
# shellcheck source=scripts/slurm/common.sh
. "$(dirname "$0")/common.sh"

m_pid=$(daemon_pid munged "$dir/munged.pid")
c_pid=$(daemon_pid slurmctld "$dir/slurmctld.pid")
d_pid=$(daemon_pid slurmd "$dir/slurmd.pid")

# Cancel the jobs through Slurm first so their steps end cleanly.
if [ -n "$c_pid" ] && [ -n "$m_pid" ] && [ -f "$conf" ]; then
  jobs=$(squeue -h -o %F 2>/dev/null | sort -u)
  if [ -n "$jobs" ]; then
    # shellcheck disable=SC2086
    scancel $jobs 2>/dev/null
    for _ in $(seq 50); do
      [ -z "$(squeue -h -t PD,R,CG,S -o %i 2>/dev/null)" ] && break
      sleep 0.2
    done
  fi
fi

# shellcheck disable=SC2046,SC2086
{
  stop_pids $d_pid
  stop_pids $c_pid
  stop_pids $(job_pids)
  stop_pids $m_pid
}

if [ -s "$dir/rundir" ]; then
  case "$(cat "$dir/rundir")" in /tmp/emaki-slurm.*) rm -rf "$(cat "$dir/rundir")" ;; esac
  rm -f "$dir/rundir"
fi
rm -f "$dir/munged.pid" "$dir/slurmctld.pid" "$dir/slurmd.pid"
exit 0
