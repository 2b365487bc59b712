"""unittest with JUnit XML output, for the Python tests that ./palcas test counts."""
import argparse
import pathlib
import sys
import unittest
from xml.sax.saxutils import quoteattr


class JUnitResult(unittest.TextTestResult):
    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.cases = []

    def add(self, test, failure, detail=""):
        cls, _, case = test.id().rpartition(".")
        self.cases.append((cls, case + detail, failure))

    def addSuccess(self, test):
        super().addSuccess(test)
        self.add(test, None)

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self.add(test, self._exc_info_to_string(err, test))

    def addError(self, test, err):
        super().addError(test, err)
        self.add(test, self._exc_info_to_string(err, test))

    def addSubTest(self, test, subtest, err):
        # A failed subTest fails its test, and unittest then reports the test neither as a
        # success nor as a failure: without this the XML would not count it at all.
        super().addSubTest(test, subtest, err)
        if err is not None:
            self.add(test, self._exc_info_to_string(err, test), " " + subtest._subDescription())


def run_as_junit(module, suite_name):
    """Runs the module's tests; with --xml FILE also writes JUnit XML for ./palcas test."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--xml")
    a = ap.parse_args()
    suite = unittest.defaultTestLoader.loadTestsFromModule(module)
    result = unittest.TextTestRunner(resultclass=JUnitResult, verbosity=2).run(suite)
    if a.xml:
        pathlib.Path(a.xml).parent.mkdir(parents=True, exist_ok=True)
        failed = sum(1 for _, _, f in result.cases if f)
        with open(a.xml, "w") as f:
            f.write('<?xml version="1.0" encoding="UTF-8"?>\n')
            f.write(f'<testsuite name="{suite_name}" tests="{len(result.cases)}" '
                    f'failures="{failed}" errors="0">\n')
            for cls, case, failure in result.cases:
                if failure:
                    f.write(f'  <testcase classname={quoteattr(cls)} name={quoteattr(case)}>'
                            f'<failure message={quoteattr(failure[-500:])}/></testcase>\n')
                else:
                    f.write(f'  <testcase classname={quoteattr(cls)} name={quoteattr(case)}/>\n')
            f.write("</testsuite>\n")
    sys.exit(0 if result.wasSuccessful() else 1)
