#!/usr/bin/env bash
# Runs every test of deflect, Rust and Python, from a fresh checkout.
# Sets up its own virtual environment in .venv (override with DEFLECT_VENV).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${DEFLECT_VENV:-.venv}"
PY="${PYTHON:-python3}"
# A clean CI checkout builds everything once: incremental caches would only take disk.
if [ "${CI:-}" = true ]; then export CARGO_INCREMENTAL=0; fi

# LinuxCNC's RS274/NGC interpreter `rs274` (Debian's linuxcnc-uspace) is the reference of the
# G-code reader (crates/core/tests/rs274.rs compares their moves live): installed where it can
# be (as root with apt-get, as CI runs), else that comparison is skipped and says so here.
if ! command -v rs274 >/dev/null 2>&1 && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  echo "== installing linuxcnc-uspace (rs274, the G-code reference) =="
  mkdir -p target
  if ! (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
          --no-install-recommends linuxcnc-uspace) > target/apt-linuxcnc.log 2>&1; then
    echo "linuxcnc-uspace could not be installed (target/apt-linuxcnc.log)"
  fi
fi
# strace lists a batch's mappings: the proof that no batch copies its input block by block
# (crates/py/tests/test_numpy.py) needs it, and is skipped without it.
if ! command -v strace >/dev/null 2>&1 && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  echo "== installing strace (the no-copy proof's mapping list) =="
  mkdir -p target
  if ! (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
          --no-install-recommends strace) > target/apt-strace.log 2>&1; then
    echo "strace could not be installed (target/apt-strace.log)"
  fi
fi
if command -v rs274 >/dev/null 2>&1; then
  echo "rs274 found: the G-code reader is compared with LinuxCNC's interpreter"
else
  echo "rs274 not found: the comparison with LinuxCNC's interpreter (rs274.rs) is skipped"
fi
if [ ! -d ../shared/machining/real ] && [ -z "${DEFLECT_SHARED:-}" ]; then
  echo "../shared/machining/real not found: the real-CAM-program comparison is skipped"
fi

echo "== Rust: format, lints, tests =="
cargo fmt --all -- --check
cargo clippy --workspace --all-targets --quiet -- -D warnings
# The tree's shape: no import circles, no file over 600 lines, no function over 100 lines
# (the listed exceptions with their reasons in the script).
python3 scripts/structure.py --check
# API docs build without a warning (broken links, missing docs) for every crate.
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet
# The C/C++ example tests link target/debug/libdeflect.a: build the static library first
# (a workspace-wide test build may only produce the rlib).
cargo build -p deflect-ffi --quiet
cargo test --workspace --quiet
# The real-time core must build without std (no_std, no alloc), and with alloc alone ...
cargo build -p deflect-core --no-default-features --quiet
cargo build -p deflect-core --no-default-features --features alloc --quiet
# ... and its per-tick paths must work from a #![no_std] crate without alloc. Build that crate
# alone: built with the workspace, cargo unifies deflect-core's features and proves nothing.
cargo build -p deflect-nostd-check --quiet
# ... and for an embedded target (Cortex-M4F/M7, hard float), the core and the crate that uses
# its per-tick paths without std or alloc: what links into a controller's firmware.
rustup target add thumbv7em-none-eabihf
cargo build -p deflect-core --no-default-features --target thumbv7em-none-eabihf --quiet
cargo build -p deflect-nostd-check --target thumbv7em-none-eabihf --quiet
# No std/alloc feature may reach nalgebra or deflect-core in that build (normal edges only:
# deflect-core's dev-dependencies enable nalgebra/std for its own tests).
if cargo tree -p deflect-nostd-check -e normal,features \
     | grep -E 'nalgebra feature "(std|alloc)"|deflect-core feature "(std|alloc)"'; then
  echo "error: the no_std build of deflect-core enables std/alloc" >&2
  exit 1
fi
# The declared rust-version (workspace Cargo.toml) is the oldest toolchain that compiles every
# crate, all targets: checked with that toolchain (its own target directory).
MSRV=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml)
rustup toolchain install "$MSRV" --profile minimal
CARGO_TARGET_DIR=target/msrv cargo +"$MSRV" check --workspace --all-targets --quiet
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
"$VENV/bin/python" -m pip install --quiet "maturin>=1.9,<2" numpy scipy pytest hypothesis mcap "example-robot-data>=4" "ruckig>=0.19" "mypy>=1.18" "dask[distributed]" ray
# The wheel is built once (abi3, release) and installed from the file; a fresh venv with
# nothing but the wheel (and numpy from its metadata) imports it: what `pip install
# deflect-robotics` gives a user.
rm -rf target/wheels
# An older install under the distribution name `deflect` would shadow the import name.
"$VENV/bin/python" -m pip uninstall --quiet -y deflect 2>/dev/null || true
"$VENV/bin/python" -m maturin build --release --quiet -m crates/py/Cargo.toml -o target/wheels
WHEEL=$(ls target/wheels/deflect_robotics-*-abi3-*.whl)
"$VENV/bin/python" -m pip install --quiet --force-reinstall --no-deps "$WHEEL"
rm -rf target/smoke-venv
"$PY" -m venv target/smoke-venv
target/smoke-venv/bin/python -m pip install --quiet "$WHEEL"
target/smoke-venv/bin/python scripts/wheel_smoke.py
# The type stubs match the compiled module: every class, signature and default.
"$VENV/bin/python" -m mypy.stubtest deflect
# ... and type checking needs none of the optional integrations (ray, dask): the same check
# with mypy reading the smoke venv's site-packages, which hold the wheel and numpy only.
printf '[mypy]\npython_executable = %s\n' "$PWD/target/smoke-venv/bin/python" > target/mypy-bare.ini
"$VENV/bin/python" -m mypy.stubtest deflect --mypy-config-file target/mypy-bare.ini
"$VENV/bin/python" -m pytest -q crates/py/tests
# Every Python snippet of README.md runs as printed.
"$VENV/bin/python" scripts/readme_snippets.py
for ex in examples/[0-9][0-9]_*.py; do
  [ -e "$ex" ] || continue
  echo "-- $ex"
  "$VENV/bin/python" "$ex" > /dev/null
done
echo "All tests passed."
