#!/usr/bin/env python3
"""Summarise the JUnit XML files that catkin's run_tests wrote.

Prints one line per failed test case, a per-file table, and finally the line
'N passed, N failed' alone on a line. Exit status 1 on any failure or when no test ran.
"""
import pathlib
import sys
import xml.etree.ElementTree as ET


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
    tail = f", {skipped} skipped" if skipped else ""
    print(f"{passed} passed, {failed} failed{tail}")
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
