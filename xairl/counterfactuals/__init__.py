"""Counterfactuals (issue 56): what would have had to be different for the policy to decide otherwise, found by a
search guided by the attributions, within the data's range and the bounds a policy declares, and checked by running
the policy on every result before it is returned or said.

The result types are plain (numpy only); :func:`counterfactual` (the search, which loads torch) is imported on
first use.
"""

from xairl import lazy_attributes
from xairl.counterfactuals.result import Change, Counterfactual, Counterfactuals, Threshold

__all__ = ["Change", "Counterfactual", "Counterfactuals", "Threshold", "counterfactual"]
__getattr__ = lazy_attributes(__name__, {"counterfactual": "xairl.counterfactuals.search"})[0]
