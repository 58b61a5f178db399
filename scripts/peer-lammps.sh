#!/usr/bin/env bash
# Run LAMMPS (Debian package `lammps`) on the benchmark case of `lbdem bench dem`: 2D bidisperse
# disks (d, 1.4d), gran/hooke/history (kn 2e4, kt 2/7 kn, gamma_n 100, mu 0.5), periodic box,
# packing fraction 0.82, slow pure shear (PEERS.md). Prints the last thermo line (step atoms ke phi
# z press pxy: z = contacts per disk) and the "Loop time" line of the timed run, from which the
# caller computes particle-steps per second. The first call for a given N_SIDE prepares the packing
# (lammps_2d_prep.in, 45,000 steps on 2 ranks: ~1 min for 10,000 disks, ~10-20 min for 100,000).
#
# Usage: scripts/peer-lammps.sh N_SIDE NP NSTEPS     (N = N_SIDE^2 disks; 100 -> 10,000; 316 -> 99,856)
# Decks: lammps_2d_prep.in / lammps_2d.in from $LBDEM_PEERS, else scripts/peers/. The prepared packing is cached in out/peer-lammps/.
set -euo pipefail
n="${1:-100}"; np="${2:-1}"; nsteps="${3:-20000}"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
peers="${LBDEM_PEERS:-}"
for cand in "$peers" "$repo/scripts/peers"; do
    if [ -n "$cand" ] && [ -f "$cand/lammps_2d.in" ]; then peers="$(cd "$cand" && pwd)"; break; fi
done
if [ ! -f "$peers/lammps_2d.in" ]; then
    echo "peer-lammps: cannot find lammps_2d.in; set LBDEM_PEERS to a directory holding the decks" >&2; exit 2
fi
if ! command -v lmp >/dev/null 2>&1; then
    echo "peer-lammps: installing Debian lammps" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y lammps openmpi-bin >&2 || { apt-get update >&2 && apt-get install -y lammps openmpi-bin >&2; }
fi
work="$repo/out/peer-lammps"; mkdir -p "$work"
rst="$work/lmp2d_n$n.restart"
run() {  # run NP ARGS...
    local p="$1"; shift
    if [ "$p" -eq 1 ]; then OMP_NUM_THREADS=1 "$@"; else
        OMP_NUM_THREADS=1 mpirun --allow-run-as-root --bind-to core -np "$p" "$@"; fi
}
cd "$peers"
if [ ! -f "$rst" ]; then
    echo "peer-lammps: preparing the n=$n packing (once)" >&2
    run 2 lmp -log "$work/prep_n$n.log" -screen none -var n "$n" -var out "$rst" -var data "$work/lmp2d_n$n.data" \
        -in lammps_2d_prep.in
fi
log="$work/run_n${n}_np$np.log"
run "$np" lmp -log "$log" -screen none -var in "$rst" -var nsteps "$nsteps" -in lammps_2d.in
grep -B1 "Loop time" "$log" | tail -2
