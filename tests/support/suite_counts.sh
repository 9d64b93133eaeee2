# Sourced by the suites outside ctest (tests/fastdds3/run.sh, tests/fastdds214/run.sh): their
# counters, ctest summaries added in, and one test of their own run with its output in a log.
# Before sourcing: logs (the log directory) and suite (the prefix of a test's name).
passed=0
failed=0
count_ctest() {  # LOG: adds ctest's "97% tests passed, 3 tests failed out of 100"
  local bad total
  if read -r bad total < <(sed -nE 's/.* tests passed, ([0-9]+) tests? failed out of ([0-9]+).*/\1 \2/p' "$1" | tail -n 1); then
    passed=$((passed + total - bad)); failed=$((failed + bad))
    # A failed test's output, which ctest --output-on-failure prints after its result line, shown
    # whole (the suites print only the result lines of their runs), its last 60 lines each.
    ((bad == 0)) || awk '/^ *[0-9]+\/[0-9]+ Test .*\*\*\*/ {keep = 1; n = 0}
                         /^ *[0-9]+\/[0-9]+ Test .*Passed|^ *Start +[0-9]+:/ {keep = 0}
                         keep && n++ < 60' "$1"
  else
    echo "$1: no ctest summary" >&2; failed=$((failed + 1))
  fi
}
check() {  # NAME COMMAND...: one test, its output in $logs/NAME.log
  local name=$1; shift
  local start=$SECONDS
  if "$@" > "$logs/$name.log" 2>&1; then
    passed=$((passed + 1)); echo "$suite.$name: passed ($((SECONDS - start)) s)"
  else
    failed=$((failed + 1)); echo "$suite.$name: FAILED ($((SECONDS - start)) s)"; tail -n 40 "$logs/$name.log"
  fi
}
