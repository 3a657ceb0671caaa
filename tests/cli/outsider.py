"""What the rounds of hostile cases written from the documentation alone (test_unseen_round*.py) share.

Under the sanitizers (CALLIGRAPHY_SANITIZED=1, set by tests/CMakeLists.txt's add_outsider_round) each case is
a run of the program about ten times slower, so a round runs only the few cases it names there.
"""
import os
import unittest

SANITIZED = os.environ.get("CALLIGRAPHY_SANITIZED") == "1"


def sanitized_subset(names):
    """A `load_tests` (unittest's protocol) that keeps every case, or under the sanitizers only the test
    methods named in `names`."""
    def load_tests(loader, tests, pattern):  # noqa: ARG001 - unittest's protocol
        if not SANITIZED:
            return tests
        chosen = unittest.TestSuite()

        def walk(suite):
            for item in suite:
                if isinstance(item, unittest.TestSuite):
                    walk(item)
                elif getattr(item, "_testMethodName", "") in names:
                    chosen.addTest(item)
        walk(tests)
        return chosen
    return load_tests
