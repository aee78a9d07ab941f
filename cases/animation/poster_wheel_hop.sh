#!/usr/bin/env bash
# The README's GIF: the poster sweep (dynamics II) near wheel hop, in slow motion. Runs the poster
# scene to 14.9 s with an animation window of 250 frames per second over [14.70, 14.90] s (the
# tyre first leaves the poster at 14.73 s, 14.7 Hz) and draws it with video.py.
# Usage: cases/animation/poster_wheel_hop.sh [OUT.gif] [MBDAE]   (default docs/figures/animation_wheel_hop.gif)
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
gif="${1:-$root/docs/figures/animation_wheel_hop.gif}"
mbdae="${2:-$root/build/mbdae}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
suspension="$root/cases/five_point_suspension"
sed -e "s|^model: model.yaml|model: $suspension/model.yaml|" -e "s|t_end: 20.0|t_end: 14.9|" \
  "$suspension/dynamics_poster.yaml" > "$work/poster.yaml"
echo "animation: {start: 14.70, end: 14.90, frame_rate: 250}" >> "$work/poster.yaml"
"$mbdae" run "$work/poster.yaml" --out "$work/out" --animation --quiet
/usr/bin/python3 "$root/cases/animation/video.py" "$work/out/animation.pvd" "$gif" --fps 10 --size 360x288 \
  --elev 10 --azim -75 --title "wheel hop, 25x slower"
