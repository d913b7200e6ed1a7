"""Large runs and files: states read chunk by chunk, Parquet parts, the Ray engine, atomic writes."""
