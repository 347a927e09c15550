"""Runs every tests/python/test_*.py with unittest and prints, as its very last line,
"N passed, N failed" (test methods; errors and unexpected successes count as failed, skips and
expected failures as passed). Exits 1 if any failed.

    cd tests && PLUME_LIBRARY=../build/libplume.so PYTHONPATH=../python /usr/bin/python3 python/run.py

Works from any directory; without PYTHONPATH the package is taken from the source tree.
"""
import os
import sys
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))


class CountingResult(unittest.TextTestResult):
    """A TextTestResult that also counts passes (successes, skips, expected failures)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.passed = 0

    def addSuccess(self, test):
        super().addSuccess(test)
        self.passed += 1

    def addSkip(self, test, reason):
        super().addSkip(test, reason)
        self.passed += 1

    def addExpectedFailure(self, test, err):
        super().addExpectedFailure(test, err)
        self.passed += 1


def main():
    t0 = time.time()
    # test modules import each other's helpers relative to this directory
    suite = unittest.defaultTestLoader.discover(HERE, pattern="test_*.py", top_level_dir=HERE)
    runner = unittest.TextTestRunner(stream=sys.stderr, verbosity=2, resultclass=CountingResult)
    result = runner.run(suite)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses)
    sys.stderr.flush()
    print("python tests: %.1f s" % (time.time() - t0))
    print("%d passed, %d failed" % (result.passed, failed))
    sys.stdout.flush()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
