"""testbed.studies."""
