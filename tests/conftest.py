"""Test-wide settings.

Hypothesis draws the same examples on every run by default (``derandomize``), so the suite that
CI runs is reproducible; ``pytest --hypothesis-profile=explore`` draws fresh random examples to
hunt for new failures (hypothesis prints a ``@reproduce_failure`` line for any it finds).
"""

from hypothesis import settings

settings.register_profile("default", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile("default")
