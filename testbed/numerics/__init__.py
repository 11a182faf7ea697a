"""testbed.numerics."""
