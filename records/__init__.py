"""Ground-motion records: readers, the benchmark catalogue, checks and a synthetic generator."""
