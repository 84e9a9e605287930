#!/bin/sh
# ode sweeps on worker processes (docs/sweep.md): the results file of 2
# workers is the 1-worker file byte for byte; a worker killed in a design is
# that design's failure row (exit 1, the signal named), reaped while the
# sweep goes on, and the sweep exits 0 with every other row unchanged; a
# SIGINT to the sweep keeps the finished rows, exits 130 and leaves no worker.
# usage: sweep_procs.sh CRANESIM
set -eu
bin=$1

# The worker processes of sweep PID (their parent is PID; comm "cranesim").
workers() {
    awk -v p="$1" '$2 == "(cranesim)" && $4 == p { print $1 }' /proc/[0-9]*/stat 2>/dev/null || true
}
# Wait (up to 120 s) until PID has N workers; print them.
wait_workers() {
    n=0
    while [ "$n" -lt 2400 ]; do
        w=$(workers "$1")
        if [ "$(echo "$w" | grep -c .)" -ge "$2" ]; then
            echo "$w"
            return 0
        fi
        kill -0 "$1" 2>/dev/null || break
        sleep 0.05
        n=$((n + 1))
    done
    echo "sweep_procs: sweep $1 never had $2 workers" >&2
    return 1
}

# 1. The same grid on 1 worker (in the process) and 2 worker processes.
# sandbox_wall: the truck on its pads, the hook swinging into the wall
# (contacts and collisions, as much of ODE as a run has).
grid="--scenario sandbox_wall --duration 3.5 --param hydraulics.components.lift_cyl.bore=0.08:0.12:3
      --param hydraulics.components.jib_cyl.bore=0.07:0.09:2
      --metrics peak_p1A,max_hook_sway,max_truck_tilt,collision_count"
rm -f procs_1.csv procs_2.csv
"$bin" sweep $grid --threads 1 --out procs_1.csv -q 2>/dev/null
out=$("$bin" sweep $grid --threads 2 --out procs_2.csv 2>/dev/null)
cmp procs_1.csv procs_2.csv
test "$(wc -l < procs_2.csv)" -eq 7
echo "$out" | grep -q "on 2 worker processes"
# Refused designs (bore <= 0) as rows, the same on 2 workers.
bad="--scenario ramp --mechanics ode --duration 0.2 --param hydraulics.components.lift_cyl.bore=-0.1:0.1:4
     --metrics peak_p1A"
rm -f procs_bad_1.csv procs_bad_2.csv
"$bin" sweep $bad --threads 1 --out procs_bad_1.csv -q
"$bin" sweep $bad --threads 2 --out procs_bad_2.csv -q
cmp procs_bad_1.csv procs_bad_2.csv
test "$(grep -c ',2,"' procs_bad_2.csv)" -eq 3
echo "sweep_procs: 2 worker processes wrote the 1-worker file byte for byte"

# 2. A worker killed (SIGKILL) in its design (designs of about 1 s of CPU
# each, so the kill lands in one).
long="--scenario ramp --mechanics ode --duration 20 --param hydraulics.components.lift_cyl.bore=0.08:0.12:6
      --metrics peak_p1A"
rm -f procs_kill_ref.csv procs_kill.csv
"$bin" sweep $long --threads 1 --out procs_kill_ref.csv -q
"$bin" sweep $long --threads 2 --out procs_kill.csv -q &
sp=$!
victim=$(wait_workers "$sp" 1 | head -n 1)
kill -KILL "$victim"
# Reaped by the sweep (a zombie keeps /proc/PID until its parent waits for
# it): /proc/victim must go while the sweep still runs.
while [ -e "/proc/$victim" ] && kill -0 "$sp" 2>/dev/null; do sleep 0.05; done
reaped_live=no
if [ ! -e "/proc/$victim" ] && kill -0 "$sp" 2>/dev/null; then reaped_live=yes; fi
rc=0
wait "$sp" || rc=$?
test "$rc" -eq 0 || { echo "sweep_procs: killed worker: exit $rc, want 0" >&2; exit 1; }
test "$reaped_live" = yes || { echo "sweep_procs: the killed worker was not reaped while the sweep ran" >&2; exit 1; }
test "$(wc -l < procs_kill.csv)" -eq 7
test "$(grep -c ',1,"the worker process running this design was killed by signal 9 (Killed)"$' procs_kill.csv)" -eq 1
# Every other row (and the header) as in the 1-worker file.
test "$(grep -c -x -F -f procs_kill.csv procs_kill_ref.csv)" -eq 6
echo "sweep_procs: a killed worker is its design's failure row, exit 0"

# 3. SIGINT: designs 0 and 1 are refused at once, 2 and 3 would run for
# hours (1e4 s simulated: a sweep that waited for them would hang the test
# into its timeout); the refused rows are kept, the running designs
# abandoned (their workers killed), no worker left.
int="--scenario ramp --mechanics ode --duration 1e4 --param hydraulics.components.lift_cyl.bore=-0.1:0.17:4
     --metrics peak_p1A"
rm -f procs_int.csv
"$bin" sweep $int --threads 2 --out procs_int.csv -q 2>procs_int.err &
sp=$!
ws=$(wait_workers "$sp" 2)
# Both workers alive and the refused designs long done (they take ms).
sleep 1
kill -INT "$sp"
rc=0
wait "$sp" || rc=$?
test "$rc" -eq 130 || { echo "sweep_procs: SIGINT: exit $rc, want 130" >&2; cat procs_int.err >&2; exit 1; }
for w in $ws; do
    if kill -0 "$w" 2>/dev/null; then echo "sweep_procs: worker $w left running" >&2; exit 1; fi
done
grep -q "interrupted (SIGINT); 2 of 4 designs kept in procs_int.csv" procs_int.err
test "$(wc -l < procs_int.csv)" -eq 3
test "$(grep -c '^[01],.*,2,"' procs_int.csv)" -eq 2
test -z "$(ls -a | grep 'procs_int.csv.' || true)"
echo "sweep_procs: SIGINT keeps the finished rows, exit 130, no worker left"
