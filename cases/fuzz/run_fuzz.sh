#!/usr/bin/env bash
# Builds the scene-loader fuzz target (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer,
# clang++-14) from the sources of core/, formulation/ and cases/ and runs it.
#
#   cases/fuzz/run_fuzz.sh [SECONDS] [libFuzzer options...]
#
# SECONDS defaults to 60. Exit status 0 if nothing was found; otherwise libFuzzer's status, with
# the reproducer in the artifact folder (printed at the end). Environment:
#   MBDAE_FUZZ_BUILD      build folder (default: build/fuzz)
#   MBDAE_FUZZ_ARTIFACTS  where crash-*, timeout-*, leak-* files go (default: BUILD/artifacts)
#   MBDAE_FUZZ_STRICT=1   also stop when a scene passes validation but build_system rejects it
#   MBDAE_FUZZ_JOBS       parallel compile jobs (default: nproc)
#   CXX_FUZZ              compiler (default: clang++-14)
# To replay one input: BUILD/scene_loader_fuzz FILE
set -euo pipefail

seconds=60
if [[ $# -gt 0 && "$1" =~ ^[0-9]+$ ]]; then
  seconds=$1
  shift
fi

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${MBDAE_FUZZ_BUILD:-$root/build/fuzz}
artifacts=${MBDAE_FUZZ_ARTIFACTS:-$build/artifacts}
cxx=${CXX_FUZZ:-clang++-14}
jobs=${MBDAE_FUZZ_JOBS:-$(nproc 2>/dev/null || echo 2)}

command -v "$cxx" >/dev/null || { echo "run_fuzz.sh: $cxx not found (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 1; }

san=(-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
cxxflags=(-std=c++17 -O1 -gline-tables-only "${san[@]}" -fsanitize=fuzzer-no-link
  -I"$root" -I/usr/include/eigen3 -I/usr/include/suitesparse
  -DMBDAE_FUZZ_SCENE_PATH="\"$here/scene.yaml\"" -Wno-unused-command-line-argument)
# Libraries: yaml-cpp and every mbdae_import_library(TARGET name [OPTIONAL]) of
# cases/package/mbdae_dependencies.cmake, the file the build finds them with (an OPTIONAL one
# only where the linker finds it: sundials_core on SUNDIALS 7).
libs=(-lyaml-cpp -lz)  # zlib: the compressed .vtp frames of core/vtk_xml.cpp
while read -r l optional; do
  if [[ -z "$optional" ]] || "$cxx" -l"$l" -shared -o /dev/null -x c /dev/null 2>/dev/null; then libs+=("-l$l"); fi
done < <(sed -n 's/^[[:space:]]*mbdae_import_library([[:space:]]*[A-Za-z_0-9]*[[:space:]][[:space:]]*\([A-Za-z_0-9.+-]*\)[[:space:]]*\(OPTIONAL\)\{0,1\}[[:space:]]*).*/\1 \2/p' "$root/cases/package/mbdae_dependencies.cmake")
[[ ${#libs[@]} -gt 2 ]] || libs+=(-lsundials_idas -lsundials_sunlinsolklu -lsundials_sunmatrixsparse -lsundials_nvecserial -lklu)

# Sources: those of the libraries mbdae_core, mbdae_formulation and mbdae_scene as listed in the
# top-level CMakeLists.txt (all of core/, formulation/ and the loader if that cannot be read).
library_sources() {
  awk -v lib="$1" '
    $0 ~ "add_library\\(" lib "[ \t]" { on = 1 }
    on {
      for (i = 1; i <= NF; ++i) if ($i ~ /\.cpp\)?$/) { f = $i; sub(/\)$/, "", f); print f }
      if ($0 ~ /\)/) on = 0
    }' "$root/CMakeLists.txt"
}
sources=()
for lib in mbdae_core mbdae_formulation mbdae_scene; do
  for f in $(library_sources "$lib"); do sources+=("$root/$f"); done
done
# The force laws, one file each, which the build takes by glob (MBDAE_FORCE_LAWS).
for f in "$root"/formulation/forces/*.cpp; do [[ -e "$f" ]] && sources+=("$f"); done
if [[ ${#sources[@]} -lt 3 ]]; then
  sources=("$root"/core/*.cpp "$root"/formulation/*.cpp "$root/cases/scene/scene_loader.cpp" "$root/cases/scene/scene_validation.cpp")
fi
sources+=("$here/scene_loader_fuzz.cpp")

mkdir -p "$build/obj" "$build/corpus" "$artifacts"
flags_file="$build/obj/flags"
flags_now="$cxx ${cxxflags[*]}"
[[ -f "$flags_file" && "$(cat "$flags_file")" == "$flags_now" ]] || { rm -f "$build"/obj/*.o; echo "$flags_now" > "$flags_file"; }

# An object is rebuilt when it is older than its source or any header it included (-MMD).
stale() {
  local obj=$1 src=$2 dep=${1%.o}.d
  [[ -f "$obj" && -f "$dep" ]] || return 0
  [[ "$src" -nt "$obj" ]] && return 0
  local f
  for f in $(sed -e 's/^[^:]*://' -e 's/\\$//' "$dep"); do
    [[ -e "$f" && "$f" -nt "$obj" ]] && return 0
  done
  return 1
}
objects=()
todo=()
for src in "${sources[@]}"; do
  rel=${src#"$root"/}
  obj="$build/obj/${rel//\//__}.o"
  objects+=("$obj")
  if stale "$obj" "$src"; then todo+=("$src:$obj"); fi
done
# clang 14 rejects lambdas that capture structured bindings (C++20; GCC accepts them in C++17).
# A source with a one-line `auto [a, b] = expr;` is compiled from a copy in BUILD/src where that
# line reads `auto a__b = expr; auto a = std::get<0>(a__b); auto b = std::get<1>(a__b);`
# (same line numbers; messages name the original file).
binding='^([[:space:]]*)auto \[([A-Za-z_0-9]+), *([A-Za-z_0-9]+)\] = (.*);[[:space:]]*$'
if [[ ${#todo[@]} -gt 0 ]]; then
  echo "run_fuzz.sh: compiling ${#todo[@]} file(s) with $cxx" >&2
  export cxx build root binding
  printf '%s\n' "${todo[@]}" | xargs -P "$jobs" -I{} bash -c '
    src=${1%%:*}; obj=${1#*:}; shift
    in=$src
    if grep -Eq "$binding" "$src"; then
      in="$build/src/${src#"$root"/}"
      mkdir -p "$(dirname "$in")"
      { echo "#line 1 \"$src\""; sed -E "s/$binding/\\1auto \\2__\\3 = \\4; auto \\2 = std::get<0>(\\2__\\3); auto \\3 = std::get<1>(\\2__\\3);/" "$src"; } > "$in"
    fi
    "$cxx" "$@" -MMD -MF "${obj%.o}.d" -c "$in" -o "$obj" || { echo "failed: $src" >&2; exit 255; }
  ' _ {} "${cxxflags[@]}"
fi
exe="$build/scene_loader_fuzz"
# The newest object, found without `ls -t | head` (under pipefail, head closing the pipe early
# makes ls die of SIGPIPE once the list outgrows one pipe write, and the script exit 141).
newest=${objects[0]}
for o in "${objects[@]}"; do
  if [[ "$o" -nt "$newest" ]]; then newest=$o; fi
done
if [[ ! -x "$exe" || "$newest" -nt "$exe" ]]; then
  "$cxx" "${san[@]}" -fsanitize=fuzzer "${objects[@]}" "${libs[@]}" -o "$exe"
fi

# New inputs go to BUILD/corpus; the seeds in cases/fuzz/corpus are only read.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
echo "run_fuzz.sh: fuzzing for ${seconds}s (artifacts in $artifacts)" >&2
status=0
"$exe" "$build/corpus" "$here/corpus" -dict="$here/scene.dict" -max_total_time="$seconds" -max_len=4096 \
  -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$artifacts/" -print_final_stats=1 "$@" || status=$?
if [[ $status -ne 0 ]]; then
  echo "run_fuzz.sh: the fuzzer stopped with status $status; reproducer(s):" >&2
  shown=0
  while read -r f && [[ $shown -lt 5 ]]; do echo "  $artifacts/$f" >&2; shown=$((shown + 1)); done < <(ls -t "$artifacts")
fi
exit $status
