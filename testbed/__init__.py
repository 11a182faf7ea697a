"""sysid-testbed: validate system-identification methods against exact physics truth.

Flow (see README): scenario file -> rig simulates (models/) -> dataset (HDF5) ->
signal chain -> identifier (identify/) -> scores against the truth -> report.

The public Python API is the names below (``testbed.__all__``), imported on first use so that
``import testbed`` stays cheap; ``docs/python-api.md`` shows them at work.  The public functions'
arguments are checked where a call enters (:mod:`testbed._api_checks`): a wrong one is an
:class:`~testbed.core.errors.ArgumentError` naming the function, the argument, the value and
what is allowed::

    import testbed
    result = testbed.run_scenario("cantilever_stiff_impact_lsq")
    result.model.print()
    print(result.scores.values["trac"])
"""

from __future__ import annotations

# first of all: the `testbed` command's signals while it imports (testbed.core.interrupts)
from testbed.core import interrupts as _interrupts  # noqa: F401  # isort: skip

import importlib
from typing import Any

__version__ = "0.1.0"

#: public name -> (module, attribute)
_API = {
    # scenarios, data, runs
    "load_scenario": ("testbed.pipeline.scenario", "load_scenario"),
    "list_scenarios": ("testbed.pipeline.scenario", "list_scenarios"),
    "scenario_from_dict": ("testbed.pipeline.scenario", "scenario_from_dict"),
    "Scenario": ("testbed.pipeline.scenario", "Scenario"),
    "generate": ("testbed.pipeline.generate", "generate"),
    "DatasetCache": ("testbed.pipeline.cache", "DatasetCache"),
    "measure": ("testbed.pipeline.signal_chain", "measure"),
    "run_scenario": ("testbed.scoring.evaluate", "run_scenario"),
    "score": ("testbed.scoring.evaluate", "score_model"),
    "RunResult": ("testbed.scoring.run", "RunResult"),
    # the run history (out/runs)
    "save_new_run": ("testbed.studies.runstore", "save_new_run"),
    "list_runs": ("testbed.studies.runstore", "list_runs"),
    "resolve_run": ("testbed.studies.runstore", "resolve_run"),
    # measured data from files (no truth)
    "read_measured": ("testbed.pipeline.importers", "read_measured"),
    "measurement_from_file": ("testbed.pipeline.importers", "measurement_from_file"),
    "identify_file": ("testbed.pipeline.fit", "identify_file"),
    "model_summary": ("testbed.pipeline.fit", "model_summary"),
    # studies
    "load_study": ("testbed.studies.study", "load_study"),
    "Study": ("testbed.studies.study", "Study"),
    "run_sweep": ("testbed.studies.sweep", "run_sweep"),
    "read_results": ("testbed.studies.results", "read_results"),
    # writing identifiers and rigs
    "IDENTIFIERS": ("testbed.pipeline.plugins", "IDENTIFIERS"),
    "RIGS": ("testbed.pipeline.plugins", "RIGS"),
    "load_plugins": ("testbed.pipeline.plugins", "load_plugins"),
    "Identifier": ("identify", "Identifier"),
    "StructuralIdentifier": ("identify", "StructuralIdentifier"),
    # model selection with scikit-learn (GridSearchCV) on a Measurement
    "MeasurementSamples": ("identify._base", "MeasurementSamples"),
    "TimeWindows": ("identify._base", "TimeWindows"),
    "split_measurement": ("identify._base", "split_measurement"),
    "Rig": ("models", "Rig"),
    "Field": ("testbed.core.schema", "Field"),
    "Measurement": ("testbed.core.measurement", "Measurement"),
    "Trajectory": ("testbed.core.measurement", "Trajectory"),
    "Dataset": ("testbed.core.dataset", "Dataset"),
    "Signal": ("testbed.core.dataset", "Signal"),
    "StructuralTruth": ("testbed.core.truth", "StructuralTruth"),
    "MechanicalTruth": ("testbed.core.truth", "MechanicalTruth"),
    "DynamicalTruth": ("testbed.core.truth", "DynamicalTruth"),
    # adding a rig kind (docs/rigs.md): its truth type, score catalogue, signal chain, scorer
    "Truth": ("testbed.core.truth", "Truth"),
    "register_truth": ("testbed.core.truth", "register_truth"),
    "truth_field": ("testbed.core.truth", "truth_field"),
    "KIND_METRICS": ("testbed.core.kinds", "METRICS"),
    "SignalChain": ("testbed.pipeline.signal_chain", "SignalChain"),
    "register_signal_chain": ("testbed.pipeline.signal_chain", "register_signal_chain"),
    "Scores": ("testbed.scoring.scorers", "Scores"),
    "register_scorer": ("testbed.scoring.scorers", "register_scorer"),
    "TestbedError": ("testbed.core.errors", "TestbedError"),
    "IdentificationError": ("testbed.core.errors", "IdentificationError"),
    "ArgumentError": ("testbed.core.errors", "ArgumentError"),
    "NotFittedError": ("testbed.core.errors", "NotFittedError"),
}

__all__ = ["__version__", *sorted(_API)]


def __getattr__(name: str) -> Any:
    try:
        module, attr = _API[name]
    except KeyError:
        raise AttributeError(f"module 'testbed' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module), attr)
    checks = importlib.import_module("testbed._api_checks")
    if name in checks.RULES:  # a public function: its arguments checked where a call enters
        value = checks.checked(name, value, __getattr__)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))
