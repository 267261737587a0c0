#!/usr/bin/env bash
# Across hosts, on one machine: the coupler and each side in a network
# namespace of its own (separate network stacks, joined by a bridge in a
# fourth namespace), a coupled run over tcp with CURVE, and an impostor in a
# fifth namespace that must not get in. Compares the history with the same
# scene run over ipc (docs/reliability.md, "Across hosts").
#   bash tools/netns_run.sh [BUILD_BIN_DIR]     (as root; default build/release/bin)
# Exit status: 0 pass, 1 fail, 77 skipped (no permission to create namespaces).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(cd "${1:-build/release/bin}" && pwd)
tag=hfmpm$$
work=$(mktemp -d /tmp/hfmpm-netns-XXXXXX)
names=(c s f x)           # coupler, solid, fluid, impostor
ips=(10.77.0.1 10.77.0.2 10.77.0.3 10.77.0.4)

cleanup() {
  for n in "${names[@]}" br; do ip netns del "$tag-$n" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

if ! ip netns add "$tag-br" 2>/dev/null; then
  echo "netns_run: cannot create network namespaces here (needs root and CAP_SYS_ADMIN); skipped"
  exit 77
fi
ip -n "$tag-br" link add br0 type bridge
ip -n "$tag-br" link set br0 up
for i in "${!names[@]}"; do
  n=${names[$i]}
  ip netns add "$tag-$n"
  ip link add "v$$$n" type veth peer name "e$$$n"
  ip link set "v$$$n" netns "$tag-br"
  ip link set "e$$$n" netns "$tag-$n"
  ip -n "$tag-br" link set "v$$$n" master br0 up
  ip -n "$tag-$n" addr add "${ips[$i]}/24" dev "e$$$n"
  ip -n "$tag-$n" link set "e$$$n" up
  ip -n "$tag-$n" link set lo up
done
in_ns() { local n=$1; shift; ip netns exec "$tag-$n" "$@"; }

# The stand-in scene shortened, and the MPM KGD (CI size) shortened: the
# transport with its message sizes, and the real physics sides.
sed 's/end_s: 1.0/end_s: 0.2/' scenarios/prescribed.scene >"$work/prescribed.scene"
cp scenarios/kgd-viscosity-ci.scene "$work/kgd.scene"
"$bin/hfmpm" keygen "$work/keys" >/dev/null

status=0
run_case() {
  local name=$1 solid=$2 fluid=$3 scene=$4; shift 4
  local out="$work/$name" ref="$work/$name-ipc"
  "$bin/hfmpm" run "$scene" --out "$ref" --quiet "$@" >/dev/null 2>&1
  in_ns c "$bin/hfmpm" coupler "$scene" --bind "tcp://${ips[0]}:5555" --keys "$work/keys/coupler.keys" \
    --out "$out" --quiet "$@" >"$work/$name-coupler.err" 2>&1 &
  local coupler=$!
  sleep 0.5
  # An impostor from another host, with its own keys and the coupler's public key, goes first.
  "$bin/hfmpm" keygen "$work/$name-other" >/dev/null
  sed -n 's/^server_public = .*/&/p' "$work/keys/side.keys" >"$work/$name-forged.keys"
  grep -E '^client_(public|secret) = ' "$work/$name-other/side.keys" >>"$work/$name-forged.keys"
  chmod 600 "$work/$name-forged.keys"
  in_ns x "$bin/$fluid" --connect "tcp://${ips[0]}:5555" --keys "$work/$name-forged.keys" --welcome-timeout 2 \
    >"$work/$name-impostor.err" 2>&1 || true
  in_ns s "$bin/$solid" --connect "tcp://${ips[0]}:5555" --keys "$work/keys/side.keys" \
    --advertise-host "${ips[1]}" --out "$out/solid" >"$work/$name-solid.err" 2>&1 &
  in_ns f "$bin/$fluid" --connect "tcp://${ips[0]}:5555" --keys "$work/keys/side.keys" \
    --out "$out/fluid" >"$work/$name-fluid.err" 2>&1 &
  local rc=0
  wait "$coupler" || rc=$?
  wait || true
  local data
  data=$(sed -n 's/.*"data_endpoint": "\([^"]*\)".*/\1/p' "$out/run.json")
  if [ "$rc" -ne 0 ]; then
    echo "netns_run: $name: FAIL: the coupler exited $rc: $(tail -2 "$work/$name-coupler.err")"
    status=1
    return
  fi
  if ! grep -q "without this run's side key" "$out/coupler.log"; then
    echo "netns_run: $name: FAIL: the impostor's refusal is not in coupler.log"
    status=1
  fi
  if ! grep -q "no answer to Hello" "$work/$name-impostor.err"; then
    echo "netns_run: $name: FAIL: the impostor got an answer: $(cat "$work/$name-impostor.err")"
    status=1
  fi
  # The same rows and values as over ipc, but the wall clock (column 9).
  if ! diff <(cut -d, -f1-8,10- "$ref/history.csv") <(cut -d, -f1-8,10- "$out/history.csv") >/dev/null; then
    echo "netns_run: $name: FAIL: the history differs from the ipc run's"
    status=1
    return
  fi
  echo "netns_run: $name: PASS: coupler at ${ips[0]}, solid at ${ips[1]} (data plane $data), fluid at ${ips[2]}," \
    "each in its own network namespace; CURVE; impostor at ${ips[3]} refused;" \
    "$(($(wc -l <"$out/history.csv") - 1)) history rows equal to the ipc run's"
}

run_case stand-ins hfmpm-prescribed-solid hfmpm-prescribed-fluid "$work/prescribed.scene"
# The 5-s scene's derived scaling, damping and film (cut to 0.3 s it would derive a slower method).
run_case mpm-kgd hfmpm-solid hfmpm-fluid "$work/kgd.scene" --set time.end_s=0.3 --set output.interval_s=0.1 \
  --set solid.mpm.density_scaling=8.3 --set solid.mpm.damping.grid_alpha_per_s=10 --set fluid.mpm.virtual_opening_m=1.4e-05
exit $status
