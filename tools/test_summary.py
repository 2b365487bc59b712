#!/usr/bin/env python3
"""Summarise the JUnit XML files that catkin's run_tests and ./palcas test's scripts wrote.

Prints one line per failed test case, a per-file table, catkin_test_results' verdict on the
same folder, and finally the line 'N passed, N failed' alone on a line (CI greps it). Exit
status 1 on any failure, when no test ran, or when catkin_test_results finds a failure.

catkin_test_results (catkin's own reader of gtest/rostest/JUnit results) decides whether the
XML holds errors or failures. Its counts are no per-test counts, though: it adds a gtest
file's <testsuites> totals to those of its <testsuite> children (each test twice), skips a
file it cannot parse without a word, and names no test. So the cases are counted here, per
<testcase> (a file that does not parse is a failure), and a failure catkin_test_results
reports that no <testcase> shows still counts as one failed.
"""
import pathlib
import subprocess
import sys
import xml.etree.ElementTree as ET

CATKIN_TEST_RESULTS = "/usr/bin/catkin_test_results"


def cases_of(path):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as err:
        return [(path.name, "unreadable result file", f"{err}")]
    out = []
    for case in root.iter("testcase"):
        name = f"{case.get('classname', '')}.{case.get('name', '')}".strip(".")
        bad = case.find("failure")
        if bad is None:
            bad = case.find("error")
        if case.find("skipped") is not None:
            out.append((name, "skipped", ""))
        elif bad is not None:
            msg = (bad.get("message") or bad.text or "").strip().splitlines()
            out.append((name, "failed", msg[0] if msg else ""))
        else:
            out.append((name, "passed", ""))
    return out


def catkin_verdict(results_dir):
    """(failed, its summary line): catkin_test_results' exit status over results_dir."""
    try:
        r = subprocess.run([CATKIN_TEST_RESULTS, str(results_dir)], capture_output=True, text=True,
                           timeout=120)
    except (OSError, subprocess.TimeoutExpired) as err:
        return True, f"catkin_test_results did not run: {err}"
    lines = (r.stdout + r.stderr).strip().splitlines()
    summary = next((l for l in reversed(lines) if l.startswith("Summary:")), lines[-1] if lines else "")
    return r.returncode != 0, summary


def main():
    results_dir = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "build/test_results")
    files = sorted(results_dir.rglob("*.xml")) if results_dir.exists() else []
    passed = failed = skipped = 0
    print(f"{'result file':60s} {'pass':>5s} {'fail':>5s}")
    for f in files:
        cases = cases_of(f)
        p = sum(1 for c in cases if c[1] == "passed")
        x = sum(1 for c in cases if c[1] in ("failed", "unreadable result file"))
        s = sum(1 for c in cases if c[1] == "skipped")
        passed, failed, skipped = passed + p, failed + x, skipped + s
        print(f"{str(f.relative_to(results_dir)):60s} {p:5d} {x:5d}")
        for name, status, msg in cases:
            if status != "passed" and status != "skipped":
                print(f"  FAILED {name}: {msg[:200]}")
    if not files:
        print("no test result files found")
        failed += 1
    else:
        catkin_failed, summary = catkin_verdict(results_dir)
        print(f"catkin_test_results: {summary}")
        if catkin_failed and not failed:
            print("  FAILED catkin_test_results: a failure or error no <testcase> shows")
            failed += 1
    if skipped:  # on its own line: the last one must stay exactly 'N passed, N failed'
        print(f"{skipped} skipped")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
