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
