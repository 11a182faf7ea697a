"""Write the round-22 beam scenarios (benchmarks/unseen/round22/b22_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round22/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys below
changed. Round 22 draws corners rounds 6-21 did not (they drew steel, aluminium, titanium, brass,
glass-epoxy, tungsten, magnesium, CFRP and nylon, 0.15-1.2 m, 5-40 segments, 2-6 sensors, the hammer at
0.1-0.9 L and the tip, 1 N-1 kN, 0.05-8 % damping from ``damping_ratio``, records of 0.5-15 s at 1-25.6
kHz, soft bases at 0.2-300 EI/L with cubic fractions 0.001-3; no round set ``gravity``,
``joint_offset``, ``damping_beta`` or ``integrator``, nor copper, nor one sensor): copper (E 117 GPa,
8960 kg/m^3) long and thin (0.6 m x 8 mm in 15 segments, mode 1 near 13 Hz: just above the 10 Hz
high-pass) and in the shipped geometry in 12 segments hit at 0.2 L under 80 N; the shipped beam in 45
segments; one sensor only (at the tip, on the clamped beam and on a soft base); four sensors evenly
spaced (0.25-1 L) on the clamped beam and on an 8 EI/L base; two sensors, at the root (0.1 L) and the
tip; gravity on with the sagged rest pose (``gravity = "removed"``) on the clamped beam (on a soft base
the scenario refuses it in one line: the sag would add a quadratic term the cubic truth does not
describe); the first hinge at the wall (``joint_offset`` 0) and at half a segment (0.5);
stiffness-proportional damping given as ``damping_beta`` (2e-5 s, mode 1 near 0.5 %); MuJoCo's
implicitfast integrator; soft bases on new draws of the families' range (5 EI/L with cubic fraction 0.2,
12 EI/L with 0.4 under 20 N, 2.5 EI/L with 0.1 under 80 N hit at 0.9 L); magnesium at 1.8 kHz with two
sensors (the 'auto' low-pass at 0.95 of the Nyquist frequency, mode 3 aliased by the ideal sampler to
370 Hz, between modes 1 and 2; a 1 ms hammer: at 1.2 kHz the scenario refuses the 0.3 ms one, no sample
falls inside it, and the 'auto' low-pass, above Nyquist); a 4 s record under 20 N. A second batch
(round22_beams_extra.toml): the hammer at 0.78 L near mode 2's node (sensors 0.39 / 0.78 / 1 L), copper
0.65 m x 8 mm (mode 1 near 11 Hz), thin magnesium (0.5 m x 5 mm, 16 segments) read at 0.1 and 1 L,
damping_beta 2e-4 s (modes 1-3 near 5 / 33 / 92 %), bases of 20 EI/L with cubic fraction 0.5 under 80 N
and of 2 EI/L with 0.5 read at 0.1 and 1 L, the shipped soft base by implicitfast, gravity on in 12
segments over 4 s, a 1e-5 s integration step (the soft base hinged at the wall is refused by the
scenario in one line). A fourth batch (round22_beams_last.toml): the shipped beam in 3 and 4 segments (2
segments under three sensors is refused by the scenario in one line). Noise 0.5 / 1.5 / 2 / 3 / 5 % and
seeds 131-136 are the studies' (round22_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

SOFT = _ROUND6.SOFT
#: copper: E [Pa], rho [kg/m^3] (no round drew it); magnesium as round 18's
CU = {"E": 117e9, "rho": 8960.0}
MG = {"E": 45e9, "rho": 1740.0}
_CU_LONG = {**CU, "length": 0.6, "thickness": 0.008, "n_segments": 15}
_S1 = sensors((1.0,))
_S4 = sensors((0.25, 0.5, 0.75, 1.0))
_SRT = sensors((0.1, 1.0))
_SN2 = sensors((0.39, 0.78, 1.0))
_S02 = sensors((0.2, 0.6, 1.0))
_S09 = sensors((0.45, 0.9, 1.0))
_F20, _F80 = {"peak_force": 20.0}, {"peak_force": 80.0}
_GRAV = {"gravity": "removed"}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # materials and geometry
    "b22_cu_L0p6_t8_n15": ("copper 0.6 m x 30 x 8 mm in 15 segments (mode 1 near 13 Hz)",
                           {**_CU_LONG}, {}, {}, {}),
    "b22_cu_n12_hit0p2_f80": ("copper in 12 segments, sensors 0.2 / 0.6 / 1 L, an 80 N hit at 0.2 L",
                              {**CU, "n_segments": 12, "sensors": _S02}, {}, {"location": _S02[0], **_F80},
                              {}),
    "b22_st_n45": ("the shipped beam in 45 segments", {"n_segments": 45}, {}, {}, {}),
    "b22_mg_fs1k8_s2": ("magnesium at 1.8 kHz, two sensors 0.5 / 1 L (mode 2 at 0.57 of Nyquist, the "
                        "'auto' low-pass 855 Hz at 0.95 of it, mode 3 aliased to 370 Hz), a 1 ms hammer",
                        {**MG, "sensors": sensors((0.5, 1.0))}, {"sample_rate": 1800.0},
                        {"pulse_duration": 1e-3}, {}),
    # sensors
    "b22_st_s1tip": ("the shipped beam read by one sensor, at the tip", {"sensors": _S1}, {}, {}, {}),
    "b22_st_s4even": ("the shipped beam, four sensors 0.25 / 0.5 / 0.75 / 1 L", {"sensors": _S4}, {}, {},
                      {}),
    "b22_st_s2roottip": ("the shipped beam, two sensors 0.1 / 1 L", {"sensors": _SRT}, {}, {}, {}),
    "b22_soft_s1tip": ("the shipped soft base read by one sensor, at the tip", {**SOFT, "sensors": _S1},
                       {}, {}, {}),
    # keys no round set
    "b22_st_grav": ("the shipped beam with gravity on, from the sagged rest pose", {}, {**_GRAV}, {}, {}),
    "b22_st_jo0": ("the shipped beam, the first hinge at the wall (joint_offset 0)", {"joint_offset": 0.0},
                   {}, {}, {}),
    "b22_st_jo0p5": ("the shipped beam, the first hinge half a segment out (joint_offset 0.5)",
                     {"joint_offset": 0.5}, {}, {}, {}),
    "b22_st_beta2e-5": ("the shipped beam, damping given as damping_beta 2e-5 s (mode 1 near 0.5 %)",
                        {"damping_ratio": 0.0, "damping_beta": 2e-5}, {}, {}, {}),
    "b22_st_implicitfast": ("the shipped beam integrated by implicitfast", {}, {"integrator": "implicitfast"},
                            {}, {}),
    # soft bases, new draws of the families' range
    "b22_soft_r5_cf0p2": ("the shipped beam on k1 = 5 EI/L, cubic fraction 0.2", {**soft(5.0, 0.2, {})}, {},
                          {}, {}),
    "b22_soft_r12_cf0p4_f20": ("the shipped beam on k1 = 12 EI/L, cubic fraction 0.4 at 20 N, under 20 N",
                               {**soft(12.0, 0.4, {}, _F20)}, {}, {**_F20}, {}),
    "b22_soft_r2p5_cf0p1_hit0p9_f80": (
        "the shipped beam on k1 = 2.5 EI/L, cubic fraction 0.1 at 80 N at 0.9 L, sensors 0.45 / 0.9 / 1 L, "
        "an 80 N hit at 0.9 L", {**soft(2.5, 0.1, {}, {"location": _S09[1], **_F80}), "sensors": _S09}, {},
        {"location": _S09[1], **_F80}, {},
    ),
    "b22_soft_r8_cf0p3_s4even": ("the shipped beam on k1 = 8 EI/L, cubic fraction 0.3, four sensors 0.25 / "
                                 "0.5 / 0.75 / 1 L", {**soft(8.0, 0.3, {}), "sensors": _S4}, {}, {}, {}),
    # records
    "b22_st_4s_f20": ("the shipped beam under 20 N, a 4 s record", {}, {"duration": 4.0}, {**_F20}, {}),
    "b22_cu_L0p6_soft_r3_cf0p3": (
        "copper 0.6 m x 30 x 8 mm in 15 segments on k1 = 3 EI/L, cubic fraction 0.3, 2 s",
        {**_CU_LONG, **soft(3.0, 0.3, _CU_LONG)}, {"duration": 2.0}, {}, {},
    ),
    # a second batch (round22_beams_extra.toml)
    "b22_st_hit_node2": ("the shipped beam, sensors 0.39 / 0.78 / 1 L, the hammer at 0.78 L (near mode 2's "
                         "node)", {"sensors": _SN2}, {}, {"location": _SN2[1]}, {}),
    "b22_cu_L0p65_t8_n15": ("copper 0.65 m x 30 x 8 mm in 15 segments (mode 1 near 11 Hz)",
                            {**CU, "length": 0.65, "thickness": 0.008, "n_segments": 15}, {}, {}, {}),
    "b22_mg_L0p5_t5_s2roottip": ("magnesium 0.5 m x 30 x 5 mm in 16 segments, sensors 0.1 / 1 L",
                                 {**MG, "length": 0.5, "thickness": 0.005, "n_segments": 16,
                                  "sensors": sensors((0.1, 1.0), 0.5)}, {}, {}, {}),
    "b22_st_beta2e-4": ("the shipped beam, damping_beta 2e-4 s (modes 1-3 near 5 / 33 / 92 %)",
                        {"damping_ratio": 0.0, "damping_beta": 2e-4}, {}, {}, {}),
    # (the shipped soft base with joint_offset 0 is refused in one line: "allowed: > 0 with base = 'soft'")
    "b22_soft_r20_cf0p5_f80": ("the shipped beam on k1 = 20 EI/L, cubic fraction 0.5 at 80 N, under 80 N",
                               {**soft(20.0, 0.5, {}, _F80)}, {}, {**_F80}, {}),
    "b22_soft_r2_cf0p5_s2roottip": ("the shipped beam on k1 = 2 EI/L, cubic fraction 0.5, sensors 0.1 / 1 L",
                                    {**soft(2.0, 0.5, {}), "sensors": _SRT}, {}, {}, {}),
    "b22_soft_implicitfast": ("the shipped soft base integrated by implicitfast", {**SOFT},
                              {"integrator": "implicitfast"}, {}, {}),
    "b22_st_grav_n12_4s": ("the shipped beam in 12 segments with gravity on, a 4 s record",
                           {"n_segments": 12}, {**_GRAV, "duration": 4.0}, {}, {}),
    "b22_st_dt1e-5": ("the shipped beam integrated at a 1e-5 s step (timestep given)", {},
                      {"timestep": 1e-5}, {}, {}),
    # a fourth batch (round22_beams_last.toml): chains of 2-4 segments (rounds drew 5-45)
    **{f"b22_st_n{n}": (f"the shipped beam in {n} segments (three sensors)", {"n_segments": n}, {}, {}, {})
       for n in (2, 3, 4)},
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 22)
