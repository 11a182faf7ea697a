"""testbed.numerics."""

from testbed.numerics.noise import noise_std, signal_band

__all__ = ["noise_std", "signal_band"]
