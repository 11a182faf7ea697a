"""testbed.core."""
