"""Narration templates: files and lookup, the bounded sandbox, tracked rendering."""
