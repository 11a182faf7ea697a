"""The cantilever as a planar chain of rigid segments, and its MuJoCo model (MJCF).

Discretisation
--------------
The beam (length ``L``, bending stiffness ``EI``, mass per length ``mu``) is cut
into ``N`` segments of length ``l = L / N``.  Hinge ``j`` (j = 0 .. N-1) sits at
``x_j = (j + a) l`` where ``a`` is :attr:`BeamParams.joint_offset`; hinge ``j``
stands for the flexibility of the beam around it, ``k_j = EI / l``, and the first
hinge for everything between the base and half a segment past it,
``k_0 = EI / ((a + 1/2) l)``.  ``a = 0`` is the vertex chain of
``rigs.md`` (root hinge ``2 EI / l``; errors -0.46 %, -1.56 % on f1, f2 at N = 10);
``a = 1/2`` is Hencky's cell-centred chain, whose errors have the opposite sign
and half the size.  ``a = 1/3`` cancels most of the leading ``N^-2`` term:
-0.14 %, -0.39 % at N = 10 (both measured against Euler-Bernoulli in the tests).
The clamped stub ``[0, a l]`` does not move.

A soft base adds a base hinge at ``x = 0`` carrying the base spring itself,
moment ``k1 q0 + k3 q0^3`` (MuJoCo 4.0 polynomial joint stiffness, exact and
native), with the stub ``[0, a l]`` as its rigid body; this needs ``a > 0``.

Every hinge gets damping ``c_j = beta k_j`` (linear coefficient), so the damping
matrix is exactly ``C = beta K``.

Coordinates: the beam lies along +x, bends in the x-z plane, thickness (bending
depth) along z, width along y.  Hinge axes are -y, so a positive joint angle
lifts the outboard beam (+z); all vertical quantities are positive upwards.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

GRAVITY = 9.81
"""Standard gravity used by the model when gravity is on [m/s^2]."""


@dataclass(frozen=True)
class BeamParams:
    """Physical and discretisation parameters of the beam.

    Parameters
    ----------
    E : float
        Young's modulus [Pa].
    rho : float
        Density [kg/m^3].
    width, thickness, length : float
        Cross-section width (y), thickness (z, the bending depth) and length (x) [m].
    n_segments : int
        Number of rigid segments ``N`` (>= 2).
    base : str
        ``"stiff"`` (clamped) or ``"soft"`` (base hinge with a nonlinear spring).
    base_k1 : float
        Linear stiffness of the soft base spring [N m/rad].
    base_k3 : float
        Cubic stiffness of the soft base spring [N m/rad^3].
    beta : float
        Stiffness-proportional damping coefficient [s]: ``C = beta K``.
    joint_offset : float
        Position of the first hinge as a fraction of a segment, ``a`` in [0, 0.5].
    """

    E: float
    rho: float
    width: float
    thickness: float
    length: float
    n_segments: int
    base: str = "stiff"
    base_k1: float = 2000.0
    base_k3: float = 0.0
    beta: float = 0.0
    joint_offset: float = 1.0 / 3.0

    @property
    def EI(self) -> float:
        """Bending stiffness [N m^2]."""
        return self.E * self.width * self.thickness**3 / 12.0

    @property
    def mass_per_length(self) -> float:
        """Mass per unit length [kg/m]."""
        return self.rho * self.width * self.thickness

    @property
    def total_mass(self) -> float:
        """Mass of the whole beam, stub included [kg] (what a lab would weigh)."""
        return self.mass_per_length * self.length

    @property
    def segment_length(self) -> float:
        """Nominal segment length ``l = L / N`` [m]."""
        return self.length / self.n_segments

    def hinges(self) -> tuple[np.ndarray, np.ndarray]:
        """Hinge positions and linear stiffnesses, root first.

        Returns
        -------
        x : ndarray, shape (n_dof,)
            Hinge positions along the beam [m].
        k : ndarray, shape (n_dof,)
            Linear rotational stiffness of each hinge [N m/rad].
        """
        n, a, l, ei = self.n_segments, self.joint_offset, self.segment_length, self.EI
        x = (np.arange(n) + a) * l
        k = np.full(n, ei / l)
        k[0] = ei / ((a + 0.5) * l)
        if self.base == "soft":
            x = np.concatenate([[0.0], x])
            k = np.concatenate([[self.base_k1], k])
        return x, k

    @property
    def n_dof(self) -> int:
        """Number of hinges (= degrees of freedom)."""
        return self.n_segments + (self.base == "soft")


def body_of(params: BeamParams, x: float) -> tuple[int, float]:
    """The moving body holding the beam point at ``x`` and the point's local offset.

    Parameters
    ----------
    x : float
        Position along the beam [m], from the root hinge (``hinges()[0][0]``) to ``length``.

    Returns
    -------
    index : int
        Body (= hinge) index, 0 at the root.
    offset : float
        Distance from that body's hinge [m].
    """
    xs, _ = params.hinges()
    i = int(np.searchsorted(xs, x, side="right") - 1)
    if i < 0:
        raise ValueError(f"x = {x} m lies inboard of the root hinge at {xs[0]} m")
    return i, float(x - xs[i])


def build_mjcf(params: BeamParams, sensors: np.ndarray, hit: float, *, timestep: float,
               integrator: str, gravity: bool) -> str:
    """MJCF text of the hinge chain with accelerometers and a hammer actuator.

    Parameters
    ----------
    params : BeamParams
    sensors : ndarray, shape (n_sensors,)
        Accelerometer positions along the beam [m].
    hit : float
        Impact position [m].
    timestep : float
        Integration step [s].
    integrator : str
        MuJoCo integrator name (``"RK4"`` or ``"implicitfast"``).
    gravity : bool
        Gravity on (-z, :data:`GRAVITY`) or off.

    Notes
    -----
    Each segment has mass ``mu * length``, centre of mass at its middle and a
    full inertia: ``I_yy = m len^2 / 12`` (the bending axis; the slender-rod value
    the Euler-Bernoulli limit needs), ``I_xx = m b^2 / 12`` and
    ``I_zz = I_xx + I_yy`` (b the width), so MuJoCo's inertia check passes at
    any N.  Sensor sites sit on the neutral axis; sensors ``acc<i>`` (accelerometer,
    site frame, z = vertical at rest), ``pos<i>`` (framepos, world) and ``vel<i>``
    (framelinvel, world) read at each site.  The hammer is a motor on site
    ``hit`` with the world site ``ref`` as reference frame, so its force is along
    world +z whatever the beam's rotation, with generalised force ``J_z^T F``.
    """
    xs, ks = params.hinges()
    ends = np.append(xs[1:], params.length)
    mu, b = params.mass_per_length, params.width
    beta = params.beta
    sites: dict[int, list[str]] = {}
    for i, s in enumerate(sensors):
        j, off = body_of(params, float(s))
        sites.setdefault(j, []).append(f'<site name="s{i + 1}" pos="{off!r} 0 0" size="0.002"/>')
    j, off = body_of(params, hit)
    sites.setdefault(j, []).append(f'<site name="hit" pos="{off!r} 0 0" size="0.002"/>')

    body_xml = ""
    for j in reversed(range(len(xs))):
        seg = float(ends[j] - xs[j])
        m = mu * seg
        iyy = m * seg**2 / 12.0
        ixx = m * b**2 / 12.0
        k1 = float(ks[j])
        stiff = f"{k1!r}"
        if params.base == "soft" and j == 0:
            stiff = f"{k1!r} 0 {float(params.base_k3)!r}"
        pos = xs[j] - (xs[j - 1] if j > 0 else 0.0)
        body_xml = (
            f'<body name="b{j}" pos="{float(pos)!r} 0 0">'
            f'<joint name="q{j}" type="hinge" axis="0 -1 0" stiffness="{stiff}" '
            f'damping="{float(beta * k1)!r}" armature="0" frictionloss="0"/>'
            f'<inertial pos="{seg / 2!r} 0 0" mass="{m!r}" '
            f'diaginertia="{ixx!r} {iyy!r} {ixx + iyy!r}"/>'
            + "".join(sites.get(j, [])) + body_xml + "</body>")
    sensor_xml = "".join(
        f'<accelerometer name="acc{i + 1}" site="s{i + 1}"/>'
        f'<framepos name="pos{i + 1}" objtype="site" objname="s{i + 1}"/>'
        f'<framelinvel name="vel{i + 1}" objtype="site" objname="s{i + 1}"/>'
        for i in range(len(sensors)))
    g = f"0 0 {-GRAVITY!r}" if gravity else "0 0 0"
    return (
        '<mujoco model="cantilever">'
        '<compiler angle="radian" autolimits="true"/>'
        f'<option timestep="{timestep!r}" integrator="{integrator}" gravity="{g}">'
        '<flag contact="disable" constraint="disable"/></option>'
        f'<worldbody><site name="ref" pos="0 0 0" size="0.001"/>{body_xml}</worldbody>'
        '<actuator><motor name="hammer" site="hit" refsite="ref" gear="0 0 1 0 0 0"/></actuator>'
        f'<sensor>{sensor_xml}</sensor>'
        '</mujoco>')
