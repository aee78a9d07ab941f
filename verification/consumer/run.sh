#!/usr/bin/env bash
# The installed packages, checked as a user would use them (.ci/run): `cmake --install` of BUILD
# into a fresh prefix; a CMake project (find_package(mbdae)) and the same program through
# pkg-config built against it, each running a dynamics step, with the prefix moved after
# installing (relocatable); the installed CLI run without LD_LIBRARY_PATH; nothing installed
# outside the prefix; the installed Python package imported from the prefix's site-packages.
#   verification/consumer/run.sh [BUILD]   (default build)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=$PWD/cases/five_point_suspension/dynamics_step.yaml

cmake --install "$build" --prefix "$work/installed" > "$work/install.log"
outside=$(grep -E "^-- (Installing|Up-to-date): " "$work/install.log" | sed -E 's/^-- [^:]+: //' | grep -v "^$work/installed/" || true)
if [ -n "$outside" ]; then echo "installed outside the prefix:"; echo "$outside"; exit 1; fi
mv "$work/installed" "$work/prefix"   # relocated: the config files must not remember the old place
prefix=$work/prefix

"$prefix/bin/mbdae" --version
"$prefix/bin/mbdae" check "$scene"
cmake -S verification/consumer -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$work/consumer" -j2 > /dev/null
"$work/consumer/consumer" "$scene"

PKG_CONFIG_PATH=$prefix/lib/pkgconfig g++ -O1 verification/consumer/main.cpp -o "$work/consumer_pc" \
  $(PKG_CONFIG_PATH=$prefix/lib/pkgconfig pkg-config --cflags --libs mbdae)
"$work/consumer_pc" "$scene"

site=$(echo "$prefix"/lib/python3*/site-packages)
PYTHONPATH=$site /usr/bin/python3 -c "
import mbdae, sys
assert mbdae.__file__.startswith('$site'), mbdae.__file__
r = mbdae.load('$scene').with_params({'analysis.dynamics.t_end': 0.5}).run()
print('python', mbdae.__version__, r.status, r.rows)
sys.exit(0 if r.ok else 3)"
echo "consumer: ok"
