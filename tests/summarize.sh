#!/usr/bin/env bash
# Prints one closing line for `make test`: every ctest run's tests plus every fuzzer, as
# "make-test: N passed, N failed". Reads the logs the Makefile tees.
#
#   tests/summarize.sh CTEST_LOG... -- FUZZ_LOG...
set -euo pipefail
passed=0
failed=0
fuzz=false
for log in "$@"; do
  if [[ $log == -- ]]; then fuzz=true; continue; fi
  if $fuzz; then
    passed=$((passed + $(grep -c '| ok |$' "$log" || true)))
    failed=$((failed + $(grep -c '\*\*crash\*\*' "$log" || true)))
  else
    # ctest: "97% tests passed, 3 tests failed out of 100"
    if ! read -r bad total < <(sed -nE 's/.* tests passed, ([0-9]+) tests? failed out of ([0-9]+).*/\1 \2/p' "$log" | tail -n 1); then
      echo "$log: no ctest summary (did ctest run?)" >&2
      failed=$((failed + 1))
      continue
    fi
    passed=$((passed + total - bad))
    failed=$((failed + bad))
  fi
done
echo "make-test: $passed passed, $failed failed"
