#!/usr/bin/env bash
# Builds the C examples against the static library libdeflect.a with plain `cc`, runs the
# status-code check (its report goes to stderr) and then a 2 kHz correction loop, whose
# output goes to stdout: the five-bar's (dalembert_y_line, default) or the serial arm's
# (DEFLECT_EXAMPLE=serial_kr300_dalembert). Extra arguments go to the loop, e.g.
# `--latency 1000000` (the serial loop takes URDF STIFFNESS TIP first).
#
#   bash examples/c/build_and_run.sh                    # builds deflect-ffi in release first
#   DEFLECT_LIB_DIR=target/debug bash examples/c/build_and_run.sh   # use an existing build
#
# Environment: DEFLECT_LIB_DIR (directory holding libdeflect.a; if unset, runs
# `cargo build --release -p deflect-ffi` and uses target/release), CC (default cc),
# DEFLECT_OUT_DIR (where the binaries go; default target/examples-c), DEFLECT_EXAMPLE (the
# loop to run).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
if [ -z "${DEFLECT_LIB_DIR:-}" ]; then
  cargo build --release --quiet -p deflect-ffi --manifest-path "$ROOT/Cargo.toml" >&2
  DEFLECT_LIB_DIR="$ROOT/target/release"
fi
OUT="${DEFLECT_OUT_DIR:-$ROOT/target/examples-c}"
mkdir -p "$OUT"
# What `cargo rustc -p deflect-ffi --crate-type staticlib -- --print native-static-libs`
# lists on Linux (glibc).
SYSLIBS=(-lgcc_s -lutil -lrt -lpthread -lm -ldl -lc)
CFLAGS=(-std=c11 -O2 -Wall -Wextra -Wpedantic -Werror -I "$ROOT/include")
for prog in status_codes dalembert_y_line serial_kr300_dalembert; do
  "${CC:-cc}" "${CFLAGS[@]}" "$ROOT/examples/c/$prog.c" "$DEFLECT_LIB_DIR/libdeflect.a" \
    "${SYSLIBS[@]}" -o "$OUT/$prog"
done
"$OUT/status_codes" "$ROOT/data/paksoy2025_compliance_oc.csv" >&2
case "${DEFLECT_EXAMPLE:-dalembert_y_line}" in
  dalembert_y_line) exec "$OUT/dalembert_y_line" "$ROOT/data/paksoy2025_compliance_oc.csv" "$@" ;;
  serial_kr300_dalembert)
    cd "$ROOT"
    exec "$OUT/serial_kr300_dalembert" "$@" ;;
  *) echo "unknown DEFLECT_EXAMPLE '$DEFLECT_EXAMPLE'" >&2; exit 2 ;;
esac
