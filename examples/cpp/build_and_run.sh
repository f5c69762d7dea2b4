#!/usr/bin/env bash
# Builds the C++ example against the static library libdeflect.a with plain `c++` and runs
# the 2 kHz correction loop; its output (stdout) equals the C example's.
#
#   bash examples/cpp/build_and_run.sh                  # builds deflect-ffi in release first
#   DEFLECT_LIB_DIR=target/debug bash examples/cpp/build_and_run.sh
#
# Environment: DEFLECT_LIB_DIR (directory holding libdeflect.a; if unset, runs
# `cargo build --release -p deflect-ffi` and uses target/release), CXX (default c++),
# DEFLECT_OUT_DIR (where the binary goes; default target/examples-cpp).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
if [ -z "${DEFLECT_LIB_DIR:-}" ]; then
  cargo build --release --quiet -p deflect-ffi --manifest-path "$ROOT/Cargo.toml" >&2
  DEFLECT_LIB_DIR="$ROOT/target/release"
fi
OUT="${DEFLECT_OUT_DIR:-$ROOT/target/examples-cpp}"
mkdir -p "$OUT"
SYSLIBS=(-lgcc_s -lutil -lrt -lpthread -lm -ldl -lc)
"${CXX:-c++}" -std=c++17 -O2 -Wall -Wextra -Wpedantic -Werror -I "$ROOT/include" \
  "$ROOT/examples/cpp/dalembert_y_line.cpp" "$DEFLECT_LIB_DIR/libdeflect.a" "${SYSLIBS[@]}" \
  -o "$OUT/dalembert_y_line_cpp"
exec "$OUT/dalembert_y_line_cpp" "$ROOT/data/paksoy2025_compliance_oc.csv" "$@"
