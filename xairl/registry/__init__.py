"""The plugin registry: hook specifications, what the core registers, lookup."""
