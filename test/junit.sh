# Shell tests' JUnit output, counted by tools/test_summary.py with the catkin tests.
# Source it, fill the arrays names[] and failures[] ("" = passed), then call
#   write_junit SUITE FILE
# ("" as FILE writes nothing). Prints the failure count.

junit_escape() {
  # bash 5.2 (patsub_replacement) reads a bare & in a replacement as the matched text:
  # escape it, or "&quot;" comes out as '"quot;' and the XML is not well-formed.
  local s="${1//&/\&amp;}"
  s="${s//</\&lt;}"; s="${s//>/\&gt;}"; s="${s//\"/\&quot;}"
  printf '%s' "${s//$'\n'/ }"
}

write_junit() {  # SUITE FILE
  local suite="$1" file="$2" failed=0 i
  for i in "${!names[@]}"; do [ -z "${failures[$i]}" ] || failed=$((failed + 1)); done
  if [ -n "$file" ]; then
    mkdir -p "$(dirname "$file")"
    {
      printf '<?xml version="1.0" encoding="UTF-8"?>\n'
      printf '<testsuite name="%s" tests="%d" failures="%d" errors="0">\n' "$suite" "${#names[@]}" "$failed"
      for i in "${!names[@]}"; do
        if [ -z "${failures[$i]}" ]; then
          printf '  <testcase classname="%s" name="%s"/>\n' "$suite" "${names[$i]}"
        else
          printf '  <testcase classname="%s" name="%s"><failure message="%s"/></testcase>\n' \
            "$suite" "${names[$i]}" "$(junit_escape "${failures[$i]}")"
        fi
      done
      printf '</testsuite>\n'
    } >"$file"
  fi
  echo "$failed"
}

# junit_script SUITE [--xml FILE] (called with the script's "$@"): the common frame of a test
# script. Sets XML, a fresh WORK folder and empty names/failures; on exit runs
# $JUNIT_ON_EXIT (e.g. stopping what the script started), writes the JUnit file, prints
# "SUITE: N passed, N failed", removes WORK (kept and named when a check failed) and exits
# 0 only if every check passed.
junit_script() {
  JUNIT_SUITE="$1"; shift
  XML=""
  [ "${1:-}" != --xml ] || XML="${2:?--xml needs a file}"
  WORK="$(mktemp -d)"
  names=() failures=()
  JUNIT_ON_EXIT=""
  trap junit_finish EXIT
}

junit_finish() {
  [ -z "$JUNIT_ON_EXIT" ] || eval "$JUNIT_ON_EXIT"
  local failed; failed="$(write_junit "$JUNIT_SUITE" "$XML")"
  if [ "$failed" -eq 0 ]; then rm -rf "$WORK"; else echo "$JUNIT_SUITE: kept $WORK for a look"; fi
  echo "$JUNIT_SUITE: $((${#names[@]} - failed)) passed, $failed failed"
  [ "$failed" -eq 0 ] && exit 0 || exit 1
}

result() {  # NAME WHY: one check ("" = passed), printed as ok / FAIL
  names+=("$1"); failures+=("$2")
  if [ -z "$2" ]; then echo "ok   $1"; else echo "FAIL $1: $2"; fi
}
