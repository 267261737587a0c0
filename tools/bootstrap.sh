#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (as root): install what is
# missing, build (release), then either run the default scene or the tests.
#   bash tools/bootstrap.sh run    # build + run scenarios/kgd-viscosity-ci.scene and plot it
#   bash tools/bootstrap.sh test   # build + ctest (every test)
#   bash tools/bootstrap.sh build  # build only
set -euo pipefail
cd "$(dirname "$0")/.."

mode=${1:-run}
case "$mode" in run|test|build) ;; *) echo "usage: $0 run|test|build" >&2; exit 2 ;; esac

packages=(build-essential cmake pkg-config libzmq3-dev cppzmq-dev libprotobuf-dev protobuf-compiler
          libeigen3-dev libhdf5-dev libgtest-dev libgmock-dev libcli11-dev python3
          python3-numpy python3-matplotlib python3-h5py)  # the last three: tools/kgd_plot.py
# The test mode also checks format and lint (tools/lint.sh) and runs across network namespaces.
[ "$mode" = test ] && packages+=(clang-format clang-tidy iproute2)  # iproute2: tools/netns_run.sh
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bootstrap: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

jobs=$(nproc)
# The test mode builds with -Werror: a warning fails CI (other modes leave the
# cached choice alone, so switching modes does not rebuild everything).
if [ "$mode" = test ]; then cmake --preset release -DHFMPM_WERROR=ON >/dev/null; else cmake --preset release >/dev/null; fi
cmake --build --preset release -j "$jobs"

case "$mode" in
  run)
    # The CI-size viscosity-dominated KGD fracture (about 40 s on 2 cores),
    # compared with the M-vertex in the printed table and in kgd.png.
    out=hfmpm-out/kgd-viscosity-ci
    build/release/bin/hfmpm run scenarios/kgd-viscosity-ci.scene --out "$out"
    /usr/bin/python3 tools/kgd_plot.py "$out" --out "$out/kgd.png"  # parameters from $out/scene.json
    echo "bootstrap: results are in $out (history.csv, run.json, solid.h5, fluid.h5, kgd.png, logs)"
    ;;
  test)
    bash tools/lint.sh
    ctest --preset release -j "$jobs"
    ;;
  build) ;;
esac
