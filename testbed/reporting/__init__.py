"""testbed.reporting."""
