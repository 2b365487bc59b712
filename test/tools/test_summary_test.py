#!/usr/bin/env python3
"""tools/test_summary.py: ./palcas test's count over JUnit files, with catkin_test_results'
verdict; the last line 'N passed, N failed' (CI greps it).

usage: test_summary_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from junit_runner import run_as_junit  # noqa: E402

SUMMARY = ROOT / "tools" / "test_summary.py"
# A gtest file: <testsuites> totals over <testsuite> children (catkin_test_results counts both).
GTEST = """<?xml version="1.0" encoding="UTF-8"?>
<testsuites tests="2" failures="0" disabled="0" errors="0" time="0.1" name="AllTests">
  <testsuite name="Fed" tests="2" failures="0" disabled="0" errors="0" time="0.1">
    <testcase name="A" status="run" time="0" classname="Fed" />
    <testcase name="B" status="run" time="0" classname="Fed" />
  </testsuite>
</testsuites>
"""
# junit_runner's file for a test whose subTest failed (its other subTests passed silently).
SUBTEST_FAILED = """<?xml version="1.0" encoding="UTF-8"?>
<testsuite name="deps" tests="2" failures="1" errors="0">
  <testcase classname="deps.T" name="test_ok"/>
  <testcase classname="deps.T" name="test_keys (package='x')"><failure message="lacks y"/></testcase>
</testsuite>
"""


def summarise(files):
    with tempfile.TemporaryDirectory() as d:
        for name, text in files.items():
            (pathlib.Path(d) / name).parent.mkdir(parents=True, exist_ok=True)
            (pathlib.Path(d) / name).write_text(text)
        r = subprocess.run([sys.executable, str(SUMMARY), d], capture_output=True, text=True, timeout=120)
    return r.returncode, r.stdout.splitlines()


class Summary(unittest.TestCase):
    def assertLastLine(self, lines, passed, failed):
        self.assertRegex(lines[-1], r"^\d+ passed, \d+ failed$")
        self.assertEqual(lines[-1], f"{passed} passed, {failed} failed")

    def test_gtest_cases_count_once_and_catkin_test_results_agrees(self):
        status, lines = summarise({"core/gtest-fed.xml": GTEST})
        self.assertEqual(status, 0, lines)
        self.assertLastLine(lines, 2, 0)
        self.assertTrue(any(l.startswith("catkin_test_results: Summary:") for l in lines), lines)

    def test_a_failed_subtest_fails_naming_it(self):
        status, lines = summarise({"core/gtest-fed.xml": GTEST, "docs/deps.xml": SUBTEST_FAILED})
        self.assertEqual(status, 1)
        self.assertLastLine(lines, 3, 1)
        self.assertIn("  FAILED deps.T.test_keys (package='x'): lacks y", lines)

    def test_an_unreadable_file_fails(self):
        # catkin_test_results passes over it in silence; the summary does not.
        status, lines = summarise({"core/gtest-fed.xml": GTEST, "x/broken.xml": "<testsuite tests="})
        self.assertEqual(status, 1)
        self.assertLastLine(lines, 2, 1)

    def test_a_failure_only_catkin_test_results_sees_counts(self):
        # A suite that says it failed without a failed <testcase> (a crashed test's totals).
        only_totals = '<testsuite name="t" tests="1" failures="1" errors="0"><testcase name="a"/></testsuite>'
        status, lines = summarise({"core/gtest-fed.xml": GTEST, "t/t.xml": only_totals})
        self.assertEqual(status, 1)
        self.assertLastLine(lines, 3, 1)
        self.assertIn("  FAILED catkin_test_results: a failure or error no <testcase> shows", lines)

    def test_no_result_files_is_a_failure(self):
        status, lines = summarise({})
        self.assertEqual(status, 1)
        self.assertLastLine(lines, 0, 1)

    def test_skipped_cases_are_said(self):
        skipped = ('<testsuite name="s" tests="2" failures="0" errors="0" skipped="1">'
                   '<testcase name="a"/><testcase name="b"><skipped/></testcase></testsuite>')
        status, lines = summarise({"s/s.xml": skipped})
        self.assertEqual(status, 0, lines)
        self.assertEqual(lines[-1], "1 passed, 0 failed", "the last line stays what CI reads")
        self.assertEqual(lines[-2], "1 skipped")


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "test_summary")
