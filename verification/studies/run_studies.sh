#!/usr/bin/env bash
# Regenerates every study of docs/work-precision.md and docs/extreme-cases.md: builds mbdae and
# work_precision, runs the work-precision study on Dynamics I and II (CSV, JSON and PNG into
# docs/studies/), writes the page's tables from those CSV files (make_tables.py), then runs the
# extreme cases (extreme/run_extreme.sh).
#
#   verification/studies/run_studies.sh [--long] [--poster-t-end T] [--no-extreme]
#
#   --long            pass --long to run_extreme.sh (the 1000 s runs)
#   --poster-t-end T  shorten Dynamics II to [0, T] s (the page then says so)
#   --no-extreme      work-precision only
# Environment: BUILD (default build/), FORMULATIONS (default index3,index2-ggl,index1: those the
# build rejects are skipped with a note), REPEAT (Dynamics I repetitions, default 5).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${BUILD:-$root/build}"
forms="${FORMULATIONS:-index3,index2-ggl,index1}"
repeat="${REPEAT:-5}"
long=()
poster_t_end=()
extreme=1
while [ $# -gt 0 ]; do
  case "$1" in
    --long) long=(--long) ;;
    --poster-t-end) shift; poster_t_end=(--t-end "$1") ;;
    --no-extreme) extreme=0 ;;
    *) echo "usage: $0 [--long] [--poster-t-end T] [--no-extreme]" >&2; exit 1 ;;
  esac
  shift
done

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target mbdae work_precision tolerance_promise fast_mechanism_study
wp="$build/verification/studies/work_precision"
out="$root/docs/studies"
mkdir -p "$out"
cd "$root"

echo "== work-precision: Dynamics I"
"$wp" --scene cases/five_point_suspension/dynamics_step.yaml --label "Dynamics I (ground step)" \
  --formulations "$forms" --tols 1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10 --repeat "$repeat" \
  --ref-rtol 1e-12 --ref-atol 1e-16 \
  --csv "$out/wp_dynamics_step.csv" --meta "$out/wp_dynamics_step.json"
/usr/bin/python3 "$here/plot_work_precision.py" "$out/wp_dynamics_step.csv" "$out/wp_dynamics_step.png" \
  --meta "$out/wp_dynamics_step.json"

echo "== work-precision: Dynamics II (three tolerances, one repetition)"
"$wp" --scene cases/five_point_suspension/dynamics_poster.yaml --label "Dynamics II (poster sweep)" \
  --formulations "$forms" --tols 1e-4,1e-6,1e-8 --repeat 1 --ref-rtol 1e-12 --ref-atol 1e-16 \
  "${poster_t_end[@]}" --csv "$out/wp_dynamics_poster.csv" --meta "$out/wp_dynamics_poster.json"
/usr/bin/python3 "$here/plot_work_precision.py" "$out/wp_dynamics_poster.csv" "$out/wp_dynamics_poster.png" \
  --meta "$out/wp_dynamics_poster.json"

echo "== the tolerance's promise: default tolerances, every case, every formulation"
"$here/run_promise.sh"

/usr/bin/python3 "$here/make_tables.py" work-precision --doc "$root/docs/work-precision.md" \
  --study "$out/wp_dynamics_step" --study "$out/wp_dynamics_poster" --promise "$out/promise.csv"
echo "tables written into docs/work-precision.md"

if [ "$extreme" = 1 ]; then
  echo "== extreme cases"
  BUILD="$build" "$here/extreme/run_extreme.sh" "${long[@]}"
fi
