"""testbed.pipeline."""
