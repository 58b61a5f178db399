#!/usr/bin/env bash
# Run LAMMPS (Debian package `lammps`) on the packing `lbdem bench dem3d --peer` wrote: dense frictional
# spheres, Hertz-Mindlin (pair_style granular), slow simple shear (scripts/peers/lammps_3d.in). Prints the
# last thermo line (step atoms ke phi z press pxy: z = contacts per sphere) and the "Loop time" line of the
# timed run, from which the caller computes particle-steps per second.
#
# Usage: scripts/peer-lammps-3d.sh DATA NP NSTEPS DT RATE
set -euo pipefail
data="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"; np="${2:-1}"; nsteps="${3:-1000}"; dt="${4:-1e-5}"; rate="${5:-1.0}"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
peers="$repo/scripts/peers"
if ! command -v lmp >/dev/null 2>&1; then
    echo "peer-lammps-3d: installing Debian lammps" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y lammps openmpi-bin >&2 || { apt-get update >&2 && apt-get install -y lammps openmpi-bin >&2; }
fi
work="$repo/out/peer-lammps"; mkdir -p "$work"
log="$work/run3d_$(basename "$data" .data)_np$np.log"
cd "$peers"
if [ "$np" -eq 1 ]; then
    OMP_NUM_THREADS=1 lmp -log "$log" -screen none -var data "$data" -var dt "$dt" -var nsteps "$nsteps" \
        -var rate "$rate" -in lammps_3d.in
else
    OMP_NUM_THREADS=1 mpirun --allow-run-as-root --bind-to core -np "$np" lmp -log "$log" -screen none \
        -var data "$data" -var dt "$dt" -var nsteps "$nsteps" -var rate "$rate" -in lammps_3d.in
fi
grep -B1 "Loop time" "$log" | tail -2
