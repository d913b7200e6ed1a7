"""Verification: whether the words a narrative shows are true of the numbers they explain."""
