"""The Explanation, its JSON form, a narrative's evidence and the notebook view."""
