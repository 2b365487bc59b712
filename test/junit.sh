# Shell tests' JUnit output, counted by tools/test_summary.py with the catkin tests.
# Source it, fill the arrays names[] and failures[] ("" = passed), then call
#   write_junit SUITE FILE
# ("" as FILE writes nothing). Prints the failure count.

junit_escape() {
  local s="${1//&/&amp;}"
  s="${s//</&lt;}"; s="${s//>/&gt;}"; s="${s//\"/&quot;}"
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
