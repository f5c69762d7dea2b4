#!/usr/bin/env bash
# Runs every test of deflect, Rust and Python, from a fresh checkout.
# Sets up its own virtual environment in .venv (override with DEFLECT_VENV).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${DEFLECT_VENV:-.venv}"
PY="${PYTHON:-python3}"

echo "== Rust: format, lints, tests =="
cargo fmt --all -- --check
cargo clippy --workspace --all-targets --quiet -- -D warnings
cargo test --workspace --quiet
# The real-time core must build without std (no_std, no alloc) ...
cargo build -p deflect-core --no-default-features --quiet
# ... and no `std` feature may reach nalgebra in that build.
if cargo tree -p deflect-core --no-default-features -e features -i nalgebra | grep -q 'nalgebra feature "std"'; then
  echo "error: the no_std build of deflect-core enables nalgebra/std" >&2
  exit 1
fi
# Benchmarks must keep compiling (they are run by hand, not timed here).
cargo bench --workspace --no-run --quiet
# The numbered examples run (built-in defaults), each next to its Python twin below.
for ex in examples/[0-9][0-9]_*.rs; do
  name=$(basename "$ex" .rs)
  echo "-- $name"
  cargo run --quiet --example "$name" > /dev/null
done

echo "== Python: build the wheel, run pytest =="
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet "maturin>=1.9,<2" numpy scipy pytest mcap "example-robot-data>=4"
"$VENV/bin/python" -m pip install --quiet ./crates/py
"$VENV/bin/python" -m pytest -q crates/py/tests
for ex in examples/[0-9][0-9]_*.py; do
  [ -e "$ex" ] || continue
  echo "-- $ex"
  "$VENV/bin/python" "$ex" > /dev/null
done
echo "All tests passed."
