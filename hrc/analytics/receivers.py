"""The analytics app's answers to the inner apps' hooks, registered when Django is ready (apps.py)."""

from hrc.analytics.selectors import measured_times
from hrc.patterns.prediction import measure_with

# A prediction (hrc.patterns) times a draft's tasks by what the plant has measured.
measure_with(measured_times)
