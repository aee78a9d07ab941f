#!/usr/bin/env bash
# Two mbdae binaries back to back on this machine (issue 27: old and new, same machine, same
# moment): the integration CPU (summary.json cpu_seconds of the dynamics steps, output samples
# included) at the suspension's wheel_z-within-1e-6-m rungs, the least of N runs each, and the
# steps. The runs alternate between the binaries so that a change of the machine's speed during
# the measurement hits both alike.
#   verification/benchmarks/back_to_back.sh OLD_MBDAE NEW_MBDAE [N]    (N default 5)
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 OLD_MBDAE NEW_MBDAE [N]" >&2; exit 1; }
old="$1"; new="$2"; n="${3:-5}"
for b in "$old" "$new"; do [ -x "$b" ] || { echo "$0: $b is not an executable" >&2; exit 1; }; done
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
echo "| scene | rtol, atol | binary | least CPU of $n (s) | steps |"
echo "|---|---|---|---|---|"
for rung in "dynamics_step 1e-2 1e-8" "dynamics_poster 3e-2 3e-8"; do
  set -- $rung
  best_old=1e300; best_new=1e300; steps_old=0; steps_new=0
  for i in $(seq "$n"); do
    for which in old new; do
      b="$old"; [ "$which" = new ] && b="$new"
      "$b" run "$root/cases/five_point_suspension/$1.yaml" --out "$tmp/$which" --quiet --rtol "$2" --atol "$3" \
        > /dev/null || { echo "$0: $b failed on $1" >&2; exit 1; }
      read -r c s < <(cpu "$tmp/$which/summary.json")
      if [ "$which" = old ]; then
        best_old=$(/usr/bin/python3 -c "print(min($best_old, $c))"); steps_old=$s
      else
        best_new=$(/usr/bin/python3 -c "print(min($best_new, $c))"); steps_new=$s
      fi
    done
  done
  printf "| %s | %s, %s | %s | %.4f | %s |\n" "$1" "$2" "$3" "$old" "$best_old" "$steps_old"
  printf "| %s | %s, %s | %s | %.4f | %s |\n" "$1" "$2" "$3" "$new" "$best_new" "$steps_new"
done
