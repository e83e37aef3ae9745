#!/usr/bin/env bash
# Side by side with a published event-driven hard-disk code (the 2D port of Smallenburg's
# algorithm, see ../shared/peers/edmd/README.md): both codes on the same 10 000-disk start
# states at area fraction 0.3 (1000 time units) and 0.7 (200), alternating, whole-process
# seconds, collisions per second and the compressibility factor Z. Each code looks at the whole
# state every 10 time units: the peer writes its measurements (`write_interval 10`), ours ends a
# step (`--dt 10`: every position written back to the world, the overlaps sampled). The
# collisions and Z do not depend on the step. OURS_DT sets another step for ours (OURS_DT=1 is
# what this script ran before, and the peer recipe's own command).
#
# usage: [OURS_DT=10] benches/edmd_side_by_side.sh [ROUNDS]   (from the checkout; default 2 rounds)
#
# Needs the peer built outside the project, as its recipe says:
#   /tmp/edmd-peer/l09rin-EDMD/Cylinder2D/mdhdd
# and our release binary (cargo build --release).
set -euo pipefail

rounds="${1:-2}"
ours_dt="${OURS_DT:-10}"
here="$(cd "$(dirname "$0")/.." && pwd)"
shared="$(cd "$here/../shared" && pwd)"
peer=/tmp/edmd-peer/l09rin-EDMD/Cylinder2D/mdhdd
ours="$here/target/release/moving_circles"
work="$(mktemp -d /tmp/edmd-side-by-side.XXXXXX)"
trap 'rm -rf "$work"' EXIT

[ -x "$peer" ] || { echo "no peer at $peer: build it as $shared/peers/edmd/README.md says" >&2; exit 1; }
[ -x "$ours" ] || { echo "no $ours: run cargo build --release first" >&2; exit 1; }

states="$shared/peers/edmd/states"
printf '%-5s %-6s %12s %9s %14s %8s\n' code phi collisions seconds collisions/s Z
for round in $(seq "$rounds"); do
  for phi in 0.3 0.7; do
    time_units=1000
    [ "$phi" = 0.7 ] && time_units=200
    run="$work/peer-$phi"
    mkdir -p "$run"
    cat > "$run/input.dat" <<EOF
N_particles 10000
initial_configuration file $states/peer_N10000_phi$phi.sph
initial_velocities file $states/peer_N10000_phi$phi-vel.xyz
time $time_units
snapshots 1000000000
write_interval 10
seed 1
EOF
    start=$(date +%s.%N)
    (cd "$run" && "$peer" input.dat > out.txt)
    seconds=$(python3 -c "print($(date +%s.%N) - $start)")
    collisions=$(grep '^Simtime:' "$run/out.txt" | tail -1 | sed 's/.*Collisions: \([0-9]*\),.*/\1/')
    pressure=$(grep '^Measured pressure' "$run/out.txt" | awk '{print $NF}')
    # The peer reports βPσ²; Z = βPσ²·π / (4φ).
    z=$(python3 -c "import math; print(f'{$pressure * math.pi / (4 * $phi):.4f}')")
    printf '%-5s %-6s %12s %9.2f %14.0f %8s\n' peer "$phi" "$collisions" "$seconds" \
      "$(python3 -c "print($collisions / $seconds)")" "$z"

    start=$(date +%s.%N)
    "$ours" run --particles "$shared/data/particles/hd10k-phi$phi.txt" --boundary periodic \
      --solver exact --seconds "$time_units" --dt "$ours_dt" --report "$work/ours-$phi.json" > /dev/null
    seconds=$(python3 -c "print($(date +%s.%N) - $start)")
    read -r collisions z < <(python3 -c "
import json; r = json.load(open('$work/ours-$phi.json')); print(r['pair_collisions'], f\"{r['z']:.4f}\")")
    printf '%-5s %-6s %12s %9.2f %14.0f %8s\n' ours "$phi" "$collisions" "$seconds" \
      "$(python3 -c "print($collisions / $seconds)")" "$z"
  done
done
