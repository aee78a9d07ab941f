#!/usr/bin/env bash
# Two mbdae builds back to back on this machine (issue 27: old and new, same machine, same
# moment). The runs alternate between the builds so that a change of the machine's speed during
# the measurement hits both alike; each figure is the least of N runs.
#   - Dynamics I and II at each build's own wheel_z-within-1e-6-m rung: the integration CPU
#     (summary.json cpu_seconds of the dynamics steps, output samples included) and the steps.
#   - Per step and per output sample on Dynamics II at its rung: the run without output
#     (--output-step 20: samples at 0 and 20 s only) divided by its steps, and the difference
#     with the run of 20001 samples divided by 20000.
#   - With OLD_SCALING and NEW_SCALING (the builds' verification/iftomm/iftomm_scaling): A02 at
#     N = 10^4, CPU per step and body (one run each: 5 to 10 s).
#
#   verification/benchmarks/back_to_back.sh OLD_MBDAE NEW_MBDAE [N]    (N default 5)
# The rungs (rtol atol), by default those of 57d2d34 (old) and of today's build (new):
#   OLD_STEP="1e-2 1e-8" OLD_POSTER="3e-2 3e-8" NEW_STEP="3e-2 3e-8" NEW_POSTER="1e-1 1e-7"
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 OLD_MBDAE NEW_MBDAE [N]" >&2; exit 1; }
old="$1"; new="$2"; n="${3:-5}"
for b in "$old" "$new"; do [ -x "$b" ] || { echo "$0: $b is not an executable" >&2; exit 1; }; done
case "$n" in ''|*[!0-9]*|0) echo "$0: N must be a positive integer, not '$n'" >&2; exit 1;; esac
declare -A rung=(
  [old dynamics_step]="${OLD_STEP:-1e-2 1e-8}" [old dynamics_poster]="${OLD_POSTER:-3e-2 3e-8}"
  [new dynamics_step]="${NEW_STEP:-3e-2 3e-8}" [new dynamics_poster]="${NEW_POSTER:-1e-1 1e-7}")
root="$(cd "$(dirname "$0")/../.." && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cpu() {  # integration CPU and steps of the dynamics steps of summary.json $1
  /usr/bin/python3 - "$1" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
st = [s for s in d["steps"] if s["type"] == "dynamics"]
print(sum(s["statistics"]["cpu_seconds"] for s in st), sum(s["statistics"]["steps"] for s in st))
PY
}
declare -A best steps
# One run of build $1 (old or new) on scene $2 with extra options $3; keeps the least CPU.
run() {
  local which="$1" scene="$2" extra="$3" b="$old" key="$1 $2${3:+ $3}" c s
  [ "$which" = new ] && b="$new"
  read -r rt at <<< "${rung[$which $scene]}"
  # shellcheck disable=SC2086
  "$b" run "$root/cases/five_point_suspension/$scene.yaml" --out "$tmp/$which" --quiet --rtol "$rt" --atol "$at" \
    $extra > /dev/null || { echo "$0: $b failed on $scene" >&2; exit 1; }
  read -r c s < <(cpu "$tmp/$which/summary.json")
  best[$key]=$(/usr/bin/python3 -c "print(min(${best[$key]:-1e300}, $c))")
  steps[$key]=$s
}
for _ in $(seq "$n"); do
  for which in old new; do
    run "$which" dynamics_step ""
    run "$which" dynamics_poster ""
    run "$which" dynamics_poster "--output-step 20"
  done
done
echo "| scene | build | rtol, atol | least CPU of $n (s) | steps |"
echo "|---|---|---|---|---|"
for scene in dynamics_step dynamics_poster; do
  for which in old new; do
    b="$old"; [ "$which" = new ] && b="$new"
    printf "| %s | %s | %s | %.4f | %s |\n" "$scene" "$b" "${rung[$which $scene]}" "${best[$which $scene]}" \
      "${steps[$which $scene]}"
  done
done
echo
echo "| Dynamics II | build | per step, no output (us) | per output sample (us) |"
echo "|---|---|---|---|"
for which in old new; do
  b="$old"; [ "$which" = new ] && b="$new"
  quiet="${best[$which dynamics_poster --output-step 20]}"; sampled="${best[$which dynamics_poster]}"
  /usr/bin/python3 -c "print('| poster | $b | %.2f | %.2f |' % (1e6 * $quiet / ${steps[$which dynamics_poster --output-step 20]}, 1e6 * ($sampled - $quiet) / 20000))"
done
if [ -n "${OLD_SCALING:-}" ] && [ -n "${NEW_SCALING:-}" ]; then
  echo
  echo "| A02, N = 10^4 | build | ms per step | us per step and body |"
  echo "|---|---|---|---|"
  for s in "$OLD_SCALING" "$NEW_SCALING"; do
    [ -x "$s" ] || { echo "$0: $s is not an executable" >&2; exit 1; }
    # The table's last line, N first; ms/step and us/step/body by their header's columns.
    "$s" 10000 2> /dev/null | tail -2 | /usr/bin/python3 -c "
import re, sys
head, row = sys.stdin.read().splitlines()
cols = re.split(r'\s{2,}', head.strip())
vals = row.split()
i = cols.index('KLU factorizations (fresh)')
vals = vals[:i] + [' '.join(vals[i:i + 2])] + vals[i + 2:]  # that column is two words: '23 (1)'
v = dict(zip(cols, vals))
print('| A02 | $s | %s | %s |' % (v['ms/step'], v['us/step/body']))"
  done
fi
