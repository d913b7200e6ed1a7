"""The policy side: what is explained, its observation and outputs."""
