"""The project's mutation check (run on demand, not in the default test run): hand-written plausible
bugs (:mod:`tests.mutation.mutations`) applied one at a time to a temporary copy of the checkout,
each followed by the few tests chosen for it; a mutation the tests do not catch is a gap in the
suite. ``python -m tests.mutation --help``; how to read and extend it: ``tests/mutation/README.md``.
"""
