"""Counterfactuals (issue 56): what would have had to be different for the policy to decide otherwise, found by a
search guided by the attributions, within the data's range and the bounds a policy declares, and checked by running
the policy on every result before it is returned or said.
"""

from .result import Change, Counterfactual, Counterfactuals, Threshold
from .search import counterfactual

__all__ = ["Change", "Counterfactual", "Counterfactuals", "Threshold", "counterfactual"]
