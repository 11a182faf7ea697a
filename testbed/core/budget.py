"""The work a scenario may ask for: memory and integration steps, checked before any simulation.

Each rig estimates its own cost from a scenario's validated tables
(:meth:`models._base.Rig.cost`, using its own stepping rule); an identifier that simulates
its model adds its steps (:meth:`identify._base.Identifier.simulation_steps`).  The loader
(:func:`testbed.pipeline.scenario.scenario_from_dict`) refuses a scenario over budget with a
:class:`~testbed.core.errors.BudgetError` naming the key that drives the cost, so a typo such as
``duration = 1e6`` costs milliseconds, not a swapped-out machine.
"""

from __future__ import annotations

from dataclasses import dataclass

from testbed.core.errors import BudgetError

#: Peak memory one scenario run may need [bytes].  4 GiB: the machine has 24 GiB shared by
#: five engineers and up to two sweep workers each; the largest shipped scenario needs well
#: under 1 GiB (2 s of the soft cantilever at 12.8 kHz, 10 s of the five-bar at 10 kHz).
MEMORY_BUDGET_BYTES = 4 * 2**30

#: Integration steps one simulation may take.  1e8: about 45 min at the 27 us per RK4 step
#: of the 10-segment cantilever measured on the shared 2-core machine (2026-11-23; the five-bar
#: costs 93 us per step); the largest shipped scenario takes about 5e5.
STEP_BUDGET = 1e8

#: CPU time one simulation may take [s]: an hour of one core.  A step count alone misjudges a
#: fine beam, whose steps cost ~N^3 (dense mass matrix): 400 segments take 3.8 ms per
#: implicit step against ~10 us for 10 segments.  A study multiplies one run by its cells, so
#: an hour per run is already a day's sweep.
CPU_BUDGET_S = 3600.0

#: Samples one record may hold, whatever its memory: 1e8 is 2.2 h at 12.8 kHz, far beyond
#: any impact or identification record, and keeps index arithmetic and progress bars sane.
SAMPLE_BUDGET = 1e8

#: Memory per recorded value (one sample of one channel) of a measured record that
#: ``testbed identify`` reads [bytes]: the most any rig budgets per sample and channel (the
#: five-bar's 1024 bytes a sample, the cantilever's 512 a sensor), for the signal chain's
#: estimates and the identifier's library matrix.  A 2e5-row CSV of 2 channels measured
#: about 200 bytes a value in all (2026-11-26).
IDENTIFY_BYTES_PER_VALUE = 1024

#: Values (samples x channels) a record read by ``testbed identify`` may hold: the memory
#: budget at :data:`IDENTIFY_BYTES_PER_VALUE`, 4,194,304 (e.g. 2e6 samples of 2 channels,
#: about 40 s to read from CSV and fit on the shared machine; 327 s of a 12.8 kHz accelerometer).
IDENTIFY_VALUE_BUDGET = MEMORY_BUDGET_BYTES // IDENTIFY_BYTES_PER_VALUE

#: Size of a text data file (CSV, SEP-005 JSON, UFF) ``testbed identify`` reads [bytes]:
#: read into Python numbers a file may take 16 bytes of memory per byte (a 2-byte value "0,"
#: becomes a 24-byte float and an 8-byte pointer), so 256 MiB keeps the read within
#: :data:`MEMORY_BUDGET_BYTES`; a record within :data:`IDENTIFY_VALUE_BUDGET` written with
#: 17 significant digits takes under 100 MiB.
IDENTIFY_TEXT_BUDGET_BYTES = MEMORY_BUDGET_BYTES // 16

#: Cells one study may expand to (scenarios, family members included, x identifiers x noise
#: levels x seeds): 1e5.  Expanding a grid takes about 0.3 ms a cell (28 s for 1e5 on the
#: shared machine), and at the families study's 0.9 s of CPU a cell 1e5 cells are a day's
#: sweep on both cores; a typo such as 1000 seeds x 1000 noise levels planned for minutes
#: in silence before.
STUDY_CELL_BUDGET = 100_000


@dataclass(frozen=True)
class Cost:
    """Estimated cost of simulating (and identifying) one scenario.

    Attributes
    ----------
    memory_bytes : float
        Peak memory [bytes] of the run (simulation, signal chain, identification).
    steps : float
        Integration steps of the simulation.
    samples : float
        Samples of the record.
    memory_key, steps_key, samples_key : str
        The scenario key that drives each figure (named in the refusal).
    memory_value, steps_value, samples_value : object
        That key's value.
    seconds : float, optional
        Estimated CPU time of the simulation [s] on one core (None: the rig does not say).
    seconds_key, seconds_value : str, object
        The key that drives it and its value.
    """

    memory_bytes: float
    steps: float
    samples: float
    memory_key: str
    steps_key: str
    samples_key: str
    memory_value: object = None
    steps_value: object = None
    samples_value: object = None
    seconds: float | None = None
    seconds_key: str = ""
    seconds_value: object = None


def check_cost(cost: Cost, file: str) -> None:
    """Refuse a scenario whose cost exceeds a budget.

    Raises
    ------
    BudgetError
        Naming the file, the key, its value, the estimate and the budget.
    """
    # (estimate, budget, key, value, what the run would need; the budget): samples first
    checks = (
        (cost.samples, SAMPLE_BUDGET, cost.samples_key, cost.samples_value,
         f"the record would hold {cost.samples:.3g} samples; the budget is "
         f"{SAMPLE_BUDGET:.3g} (testbed.core.budget.SAMPLE_BUDGET)"),
        (cost.steps, STEP_BUDGET, cost.steps_key, cost.steps_value,
         f"the simulation would take {cost.steps:.3g} integration steps; the "
         f"budget is {STEP_BUDGET:.3g} (testbed.core.budget.STEP_BUDGET)"),
        (cost.seconds, CPU_BUDGET_S, cost.seconds_key, cost.seconds_value,
         "" if cost.seconds is None else
         f"the simulation would take about {cost.seconds / 3600:.3g} h of CPU; the "
         f"budget is {CPU_BUDGET_S / 3600:g} h (testbed.core.budget.CPU_BUDGET_S)"),
        (cost.memory_bytes, MEMORY_BUDGET_BYTES, cost.memory_key, cost.memory_value,
         f"the run would need about {cost.memory_bytes / 2**30:.3g} GiB of memory; "
         f"the budget is {MEMORY_BUDGET_BYTES / 2**30:g} GiB "
         "(testbed.core.budget.MEMORY_BUDGET_BYTES)"),
    )
    for estimate, budget, key, value, why in checks:
        # "not <=": a NaN estimate is over budget (never a pass); None: the rig does not say
        if estimate is not None and not estimate <= budget:
            raise BudgetError(file, key, value, why)


def check_steps(steps: float, file: str, key: str, value: object) -> None:
    """Refuse an identifier simulation of more than :data:`STEP_BUDGET` steps."""
    if not steps <= STEP_BUDGET:
        raise BudgetError(file, key, value,
                          f"simulating the identified model would take {steps:.3g} steps; the "
                          f"budget is {STEP_BUDGET:.3g} (testbed.core.budget.STEP_BUDGET)")
