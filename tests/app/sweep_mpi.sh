#!/bin/sh
# The same 2-parameter grid sweep on one thread and on 2 MPI ranks over
# loopback: rank 0 must write the same results file, byte for byte.
# usage: sweep_mpi.sh CRANESIM MPIEXEC
set -eu
bin=$1
mpiexec=$2
grid="--scenario ramp --duration 2 --param hydraulics.components.lift_cyl.bore=0.08:0.12:3 --param hydraulics.components.jib_cyl.bore=0.07:0.09:2"
rm -f sweep_mpi_ref.csv sweep_mpi_2.csv
"$bin" sweep $grid --threads 1 --out sweep_mpi_ref.csv -q
# As root Open MPI wants its consent; --oversubscribe: 2 ranks on fewer cores.
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,tcp OMPI_MCA_btl_tcp_if_include=lo \
  "$mpiexec" --oversubscribe -np 2 "$bin" sweep $grid --out sweep_mpi_2.csv -q
cmp sweep_mpi_ref.csv sweep_mpi_2.csv
test "$(wc -l < sweep_mpi_2.csv)" -eq 7
echo "sweep_mpi: 2 ranks wrote the 1-thread file byte for byte"
# Refused designs (bore <= 0) on both ranks: the same rows as a local run;
# with --fail-fast the ranks stop, exit 1, no hang.
bad="--scenario ramp --duration 1 --param hydraulics.components.lift_cyl.bore=-0.1:0.1:4 --metrics peak_p1A"
rm -f sweep_mpi_bad_ref.csv sweep_mpi_bad_2.csv
"$bin" sweep $bad --threads 1 --out sweep_mpi_bad_ref.csv -q
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,tcp OMPI_MCA_btl_tcp_if_include=lo \
  timeout 120 "$mpiexec" --oversubscribe -np 2 "$bin" sweep $bad --out sweep_mpi_bad_2.csv -q
cmp sweep_mpi_bad_ref.csv sweep_mpi_bad_2.csv
rc=0
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl=self,tcp OMPI_MCA_btl_tcp_if_include=lo \
  timeout 120 "$mpiexec" --oversubscribe -np 2 "$bin" sweep $bad --fail-fast --out sweep_mpi_ff.csv -q 2>/dev/null || rc=$?
test "$rc" -eq 1
echo "sweep_mpi: failing designs as rows on 2 ranks; --fail-fast exits 1"
