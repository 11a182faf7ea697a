"""The lab's signal chain: from a Dataset's measured signals to a Measurement.

``SIGNAL_SCHEMAS[kind]`` is the schema of a scenario's ``[signal]`` table for a
rig of that kind.
"""

from __future__ import annotations

from testbed.schema import Field

SIGNAL_SCHEMAS: dict[str, dict[str, Field]] = {
    "structural": {
        "highpass_hz": Field(float, 10.0, unit="Hz", min=0.0, min_inclusive=False,
                             doc="cut-off of the zero-phase elliptic high-pass applied after each "
                                 "integration (removes drift)"),
        "highpass_order": Field(int, 4, min=1, max=12, doc="order of the elliptic high-pass"),
        "ripple_db": Field(float, 0.1, unit="dB", min=0.0, min_inclusive=False,
                           doc="pass-band ripple of the elliptic filter (the paper: 0.1 dB)"),
        "stop_db": Field(float, 30.0, unit="dB", min=0.0, min_inclusive=False,
                         doc="stop-band attenuation of the elliptic filter (the paper: 30 dB)"),
        "lowpass_hz": Field(float, 0.0, unit="Hz", min=0.0,
                            doc="optional zero-phase low-pass cut-off; 0 = off"),
        "lowpass_order": Field(int, 8, min=1, max=16, doc="order of the optional low-pass"),
    },
    "mechanical": {
        "derivatives": Field(str, "recorded", choices=("recorded", "estimated"),
                             doc="use the recorded joint rates and accelerations, or estimate "
                                 "them from the measured angles"),
        "window": Field(int, 201, min=5, doc="Savitzky-Golay window [samples] for estimated "
                                             "derivatives (odd)"),
        "polyorder": Field(int, 4, min=2, max=8, doc="Savitzky-Golay polynomial order"),
    },
}
