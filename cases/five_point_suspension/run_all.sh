#!/usr/bin/env bash
# Runs every analysis of the five-point suspension (equilibrium, kinematics, dynamics I and II)
# into OUT (default: build/five_point_suspension), then draws figures 2-9 into OUT/figures and
# docs/figures. Usage: cases/five_point_suspension/run_all.sh [OUT] [MBDAE]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/build/five_point_suspension}"
mbdae="${2:-$root/build/mbdae}"
mkdir -p "$out"
for scene in equilibrium kinematics dynamics_step dynamics_poster; do
  echo "== $scene"
  "$mbdae" run "$here/$scene.yaml" --out "$out/$scene"
done
/usr/bin/python3 "$here/plot_figures.py" "$out" "$root/docs/figures"
echo "results in $out"
