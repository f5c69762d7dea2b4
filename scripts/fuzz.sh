#!/usr/bin/env bash
# Fuzzes deflect's loaders: every cargo-fuzz target of fuzz/ (or those named) for SECONDS
# each, one after the other, and prints the executions per second of each target.
#
#   scripts/fuzz.sh SECONDS [TARGET...]
#
# The committed seed corpus fuzz/corpus/<target>/ is read; the inputs the fuzzer adds go to
# fuzz/work/<target>/ (not committed, kept between runs). After a clean run the committed
# corpus is chosen again from both: its seed_* files plus the inputs that add the most
# coverage, FUZZ_CORPUS_MAX (40) in all, so that it stays small (`cargo fuzz cmin` keeps
# thousands); FUZZ_CMIN=0 leaves it alone.
#
# A crash, leak, timeout or out-of-memory input is copied to fuzz/regressions/<target>/
# (replayed by tests/fuzz_replay.rs from then on, also after the fix) and makes the script
# exit non-zero.
#
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz --locked`). Not run by
# CI: CI replays the corpus and the regressions on stable (cargo test --test fuzz_replay).
set -uo pipefail
cd "$(dirname "$0")/.."

if [ $# -lt 1 ] || ! [[ "$1" =~ ^[0-9]+$ ]]; then
  echo "usage: scripts/fuzz.sh SECONDS [TARGET...]" >&2
  exit 2
fi
secs="$1"
shift
if [ $# -gt 0 ]; then
  targets=("$@")
else
  targets=(urdf_stiffness map_csv static_csv map_json drive_toml gcode tool_table)
fi

cargo +nightly fuzz build || exit 1

# At most this many committed inputs per target (all targets together stay near 200 files).
max_corpus="${FUZZ_CORPUS_MAX:-40}"

# minimise TARGET CORPUS WORK TMPDIR: prints a directory with the named seeds of CORPUS and
# at most max_corpus inputs in all, picked greedily from CORPUS and WORK by the coverage they
# add (libFuzzer merge control files), 10 a round. cmin alone keeps thousands of inputs.
minimise() {
  local t="$1" corpus="$2" work="$3" tmp="$4" round=0 want picked f
  local sel="$tmp/sel"
  mkdir -p "$sel"
  cp "$corpus"/seed_* "$sel"/ 2>/dev/null || true
  while [ "$(find "$sel" -type f | wc -l)" -lt "$max_corpus" ]; do
    round=$((round + 1))
    want=$((max_corpus - $(find "$sel" -type f | wc -l)))
    [ "$want" -gt 10 ] && want=10
    # The merge's first directory is a copy of the selection: its coverage counts first, and
    # each other input's FT line lists only the features it adds to it.
    cp -r "$sel" "$tmp/out$round"
    cargo +nightly fuzz run "$t" "$tmp/out$round" "$corpus" "$work" -- -merge=1 \
      -merge_control_file="$tmp/ctl$round" -rss_limit_mb=2048 -timeout=30 \
      >"$tmp/merge$round.log" 2>&1 || return 1
    picked=$(awk -v want="$want" '
      NR == 1 { n = $1; next }
      NR == 2 { first = $1; next }
      NR <= n + 2 { path[NR - 3] = $0; next }
      $1 == "FT" && $2 >= first && NF > 2 { print NF - 2, path[$2] }' "$tmp/ctl$round" |
      sort -k1,1nr -k2 | head -n "$want" | cut -d" " -f2-)
    rm -rf "$tmp/out$round"
    [ -n "$picked" ] || break
    while IFS= read -r f; do cp "$f" "$sel/"; done <<<"$picked"
  done
  echo "$sel"
}

logdir=$(mktemp -d)
failed=()
summary=()
for t in "${targets[@]}"; do
  corpus="fuzz/corpus/$t"
  work="fuzz/work/$t"
  artifacts="fuzz/artifacts/$t"
  mkdir -p "$corpus" "$work" "$artifacts" "fuzz/regressions/$t"
  marker="$logdir/$t.start"
  touch "$marker"
  log="$logdir/$t.log"
  echo "== $t: ${secs} s (log $log)"
  # New inputs go to the first directory (work); the committed corpus is read as seeds.
  cargo +nightly fuzz run "$t" "$work" "$corpus" -- \
    -max_total_time="$secs" -rss_limit_mb=2048 -timeout=30 -print_final_stats=1 \
    >"$log" 2>&1
  status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1)
  found=()
  while IFS= read -r f; do
    [ -n "$f" ] || continue
    cp "$f" "fuzz/regressions/$t/"
    found+=("$(basename "$f")")
  done < <(find "$artifacts" -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' \
             -o -name 'oom-*' \) -newer "$marker")
  if [ "$status" -ne 0 ] || [ ${#found[@]} -gt 0 ]; then
    failed+=("$t")
    echo "!! $t: exit $status; new reproducers in fuzz/regressions/$t/: ${found[*]:-none}"
    grep -E -m 5 'panicked at|ERROR: libFuzzer|SUMMARY' "$log" | sed 's/^/   /'
  elif [ "${FUZZ_CMIN:-1}" != 0 ]; then
    before=$(find "$corpus" -type f | wc -l)
    if min=$(minimise "$t" "$corpus" "$work" "$logdir/$t.min"); then
      rm -rf "$corpus" && mv "$min" "$corpus"
      echo "   committed corpus: $before -> $(find "$corpus" -type f | wc -l) files," \
           "$(du -sh "$corpus" | cut -f1); the work corpus keeps $(find "$work" -type f | wc -l)"
    else
      echo "!! $t: minimising failed (logs in $logdir/$t.min); corpus unchanged"
    fi
  fi
  summary+=("$(printf '%-16s %12s runs  %8s exec/s  %s' "$t" "${runs:-?}" "${rate:-?}" "${cov:-}")")
done

echo "== executions per second (${secs} s each)"
printf '%s\n' "${summary[@]}"
if [ ${#failed[@]} -gt 0 ]; then
  echo "crashes in: ${failed[*]} (inputs copied to fuzz/regressions/)" >&2
  exit 1
fi
echo "no crash"
