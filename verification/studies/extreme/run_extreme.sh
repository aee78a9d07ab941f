#!/usr/bin/env bash
# Runs the stiff and extreme cases of verification/studies/extreme/*.yaml with `mbdae run`, each
# (when it has one) against a reference run, and regenerates the table of docs/extreme-cases.md
# (the hand-written part of that page is kept; see verification/studies/make_tables.py).
#
#   verification/studies/extreme/run_extreme.sh [--long] [--only NAME[,NAME...]]
#
#   --long   also run the 1000 s cases (poster_1000s_slow_sweep: about 1.5 minutes of CPU;
#            poster_1000s, the spec's sweep continued to 901 Hz: about 6 minutes of CPU at commit
#            910af29, see docs/extreme-cases.md). Without --long their last stored results are
#            kept in the table.
#   --only   run only these cases (the table is still rebuilt from every stored result).
# Environment: BUILD (default build/), OUT (raw run folders, default BUILD/studies/extreme).
# Per-case results: docs/studies/extreme/NAME.json. Exit code 0 unless a case's outcome could not
# be collected (a case that fails the way its documentation says is not an error of this script).
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
build="${BUILD:-$root/build}"
mbdae="$build/mbdae"
out="${OUT:-$build/studies/extreme}"
results="$root/docs/studies/extreme"
doc="$root/docs/extreme-cases.md"
tables="$root/verification/studies/make_tables.py"
py=/usr/bin/python3

long=0
only=""
while [ $# -gt 0 ]; do
  case "$1" in
    --long) long=1 ;;
    --only) shift; only=",${1:-},";;
    *) echo "usage: $0 [--long] [--only NAME[,NAME...]]" >&2; exit 1 ;;
  esac
  shift
done
[ -x "$mbdae" ] || { echo "run_extreme: no $mbdae (build first)" >&2; exit 1; }
mkdir -p "$out" "$results"

step="cases/five_point_suspension/dynamics_step.yaml"
# name | reference | long (1: only with --long). Reference: "self A;B;..." (the same scene with
# the overrides A, else B, ...: the first that runs to the end; tight index-3 runs of these scenes
# fail at some tolerances, see docs/extreme-cases.md), "scene FILE" (another scene at its own
# tolerances) or "-" (none).
cases=(
  "step_loose_tolerance|self --rtol 1e-12 --atol 1e-16;--rtol 1e-11 --atol 1e-17|0"
  "step_tight_tolerance|-|0"
  "tyre_stiffness_x100|self --rtol 1e-10 --atol 1e-16;--rtol 1e-10 --atol 1e-15;--rtol 1e-9 --atol 1e-14|0"
  "tyre_stiffness_x10000|self --rtol 1e-10 --atol 1e-16;--rtol 1e-9 --atol 1e-15;--rtol 1e-9 --atol 1e-12|0"
  "damping_zero|self --rtol 1e-10 --atol 1e-16;--rtol 1e-10 --atol 1e-15;--rtol 3e-10 --atol 3e-16|0"
  "damping_x100|self --rtol 1e-10 --atol 1e-16;--rtol 1e-10 --atol 1e-15|0"
  "poster_sweep_50hz|self --rtol 1e-10 --atol 1e-16;--rtol 1e-10 --atol 1e-15|0"
  "kinematics_travel_ends|self --rtol 1e-13 --atol 1e-13;--rtol 1e-12 --atol 1e-12|0"
  "kinematics_past_travel|self --rtol 1e-13 --atol 1e-13;--rtol 1e-12 --atol 1e-12|0"
  "rough_guess_10deg_plus|scene $step|0"
  "rough_guess_10deg_minus|scene $step|0"
  "rough_guess_60deg_plus|scene $step|0"
  "rough_guess_90deg_minus|-|0"
  "poster_50s|-|0"
  "poster_1000s_slow_sweep|-|1"
  "poster_1000s|-|1"
)


order=""
status=0
for entry in "${cases[@]}"; do
  IFS='|' read -r name refspec is_long <<<"$entry"
  order="$order${order:+,}$name"
  if [ -n "$only" ] && [[ "$only" != *",$name,"* ]]; then continue; fi
  if [ "$is_long" = 1 ] && [ "$long" = 0 ]; then
    echo "== $name: long case, skipped without --long (table keeps its last result)"
    continue
  fi
  scene="verification/studies/extreme/$name.yaml"
  echo "== $name"
  rm -rf "$out/$name" "$out/$name.ref"
  t0=$(date +%s.%N)
  "$mbdae" run "$root/$scene" --out "$out/$name" --quiet 2>"$out/$name.stderr"
  code=$?
  t1=$(date +%s.%N)
  wall=$($py -c "print('%.3f' % ($t1 - $t0))")
  refargs=()
  refnotes=""
  if [ "$refspec" != "-" ]; then
    kind="${refspec%% *}"
    rest="${refspec#* }"
    if [ "$kind" = self ]; then
      # Candidates in order; a run that stops early (e.g. past the travel) is kept if none reaches
      # the end: its samples up to the failure are still compared.
      IFS=';' read -r -a candidates <<<"$rest"
      refnotes=""
      for cand in "${candidates[@]}"; do
        rm -rf "$out/$name.ref"
        # shellcheck disable=SC2086
        "$mbdae" run "$root/$scene" --out "$out/$name.ref" --quiet $cand 2>"$out/$name.ref.stderr"
        refcode=$?
        label="same scene, ${cand//--/}"
        [ "$refcode" = 0 ] && break
        why="$(grep -o 'IDA failed at t = [^ ]*' "$out/$name.ref/summary.json" | head -1)"
        echo "   reference with $cand: exit $refcode ($why)"
        refnotes="$refnotes${refnotes:+; }${cand//--/}: exit $refcode, $why"
      done
    else
      "$mbdae" run "$root/$rest" --out "$out/$name.ref" --quiet 2>"$out/$name.ref.stderr"
      refcode=$?
      label="$rest"
    fi
    refargs=(--ref "$out/$name.ref" --ref-exit "$refcode" --ref-label "$label" --ref-notes "$refnotes")
  fi
  longflag=()
  [ "$is_long" = 1 ] && longflag=(--long)
  $py "$tables" extreme-case --name "$name" --scene "$scene" --run "$out/$name" --exit "$code" --wall "$wall" \
    --stderr "$out/$name.stderr" "${refargs[@]}" "${longflag[@]}" --json "$results/$name.json" || status=1
done

$py "$tables" extreme-doc --results "$results" --doc "$doc" --order "$order" || status=1
echo "table written into $doc"
exit $status
