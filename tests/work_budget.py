"""Work counted, not timed: the function calls a piece of code makes (Python's and built-in ones, as cProfile counts
them), for tests that bound work without a clock.

A test that asserted a wall-clock limit failed under load (2.01 s against 2.0 s, issue 51); the calls a rendering
or a verification makes are the same on any machine and under any load, and a runaway loop or a quadratic reading
still shows as many more of them. Work done inside one C call (a regular expression's backtracking, a string
built by ``*``) is not counted here: ``tests/regex_steps.py`` counts a pattern's steps, and the sandbox sizes what
a template builds before it is built. The times themselves are in ``benchmarks/bench_test_timings.py``.
"""

from __future__ import annotations

import cProfile


def calls(fn, *args, **kwargs):
    """Run ``fn(*args, **kwargs)``; return ``(its result, the calls it made)``. An exception of ``fn`` is raised as
    it is, with the count on it as ``exc.calls``."""
    profile = cProfile.Profile()
    profile.enable()
    try:
        result = fn(*args, **kwargs)
    except Exception as exc:
        profile.disable()
        exc.calls = _count(profile)
        raise
    profile.disable()
    return result, _count(profile)


def _count(profile: cProfile.Profile) -> int:
    return sum(entry.callcount for entry in profile.getstats())
