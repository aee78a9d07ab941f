#!/usr/bin/env bash
# Runs every analysis of the five-point suspension (equilibrium, kinematics, dynamics I and II)
# into OUT (default: build/five_point_suspension), then draws figures 2-9 into OUT/figures and
# docs/figures, and each analysis as a ParaView time series (OUT/SCENE/animation.pvd) and a
# quick-look video (OUT/SCENE/animation.mp4, docs/animation.md).
# Usage: cases/five_point_suspension/run_all.sh [OUT] [MBDAE]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/build/five_point_suspension}"
mbdae="${2:-$root/build/mbdae}"
mkdir -p "$out"
for scene in equilibrium kinematics dynamics_step dynamics_poster; do
  echo "== $scene"
  "$mbdae" run "$here/$scene.yaml" --out "$out/$scene" --animation
done
for scene in equilibrium kinematics dynamics_step dynamics_poster; do
  # The 20 s poster sweep as a 300-frame time lapse (the other runs in real time).
  /usr/bin/python3 "$root/cases/animation/video.py" "$out/$scene/animation.pvd" "$out/$scene/animation.mp4" \
    --max-frames 300 --title "$scene"
done
/usr/bin/python3 "$here/plot_figures.py" "$out" "$root/docs/figures"
echo "results in $out"
