"""frictionid: identify friction models from the free vibration of an oscillator.

The functions take the configuration's tables as dicts (``oscillator``, ``model``, ``fit``,
``energy``) and records as dicts of arrays, call the same engine as the ``frictionid``
command line, and return result objects: the same structure as its report.json (a dict,
with numpy arrays for the series), plus a parameter table, the text report, a plot and a
notebook view. Units are SI (m, s, kg, N). The ``oscillator`` dict may give one standard
deviation of each property (``mass_std``, ``damping_std``, ``stiffness_std``,
``normal_force_std``): every fitted parameter then reports ``std_error_components`` and a
total ``std_error``.

- ``models()``: every registered model (``frictionid models --json``).
- ``simulate(oscillator, model, x0, t, v0=0.0, options=None)``: one free vibration, a
  ``SimulateResult``.
- ``fit(oscillator, model, records, fit=None)``: a model fitted to records, a ``FitResult``.
- ``compare(oscillator, models, records, fit=None)``: several models ranked, with the law to
  use, a ``CompareResult``.
- ``energy(oscillator, records, model=None, options=None)``: the energy-based force (Eq. 7),
  an ``EnergyResult``.
- ``plan(oscillator, model, plan, records=None, fit=None)``: which records to take next
  (``frictionid plan``; ``plan`` is the ``[plan]`` table), report.json's dict.
- ``run(config_path, command="fit", out=None)``: a configuration file, as the CLI runs it;
  returns what the function of the same name returns. Nothing is written unless ``out``
  names a folder (then the CLI's report folder is written there too).
- ``campaign(config, manifest=None, executor=None, out=None)``: every group of a campaign
  (one task per group on any ``concurrent.futures`` executor), campaign.csv as a pandas
  DataFrame (pandas: ``pip install frictionid[campaign]``).

Every result keeps dict access (``result["parameters"]``) and adds ``.params`` (a pandas
DataFrame indexed by parameter: ``value``, ``std_error``, ``ci_low``, ``ci_high``, ``unit``,
``status``), ``.report()`` (the summary the CLI prints; ``report("markdown")``: report.md),
``.plot()`` (a matplotlib Figure), ``.verdict`` and ``_repr_html_`` for notebooks. pandas
and matplotlib are needed only for ``.params`` and ``.plot()``: ``pip install
frictionid[notebook]``. A ``CompareResult`` adds ``.recommended`` (the recommended law's
``FitResult``), ``.results`` (every law's, by name) and ``.ranking_table``. A ``FitResult``
(and a comparison) has ``export(lang="c", prefix="fid_", normal_force=None)``, the fitted
law (a comparison's recommended one) as C, Rust or Python source text, or ``lang="table"``
for the steady-state compensation table (``frictionid export``).

Bad input raises ``ValueError``; a fit that failed raises ``FitError``. Ctrl-C stops a fit.
"""

from . import _native
from ._native import FitError, models, plan
from .campaign import campaign
from .results import CompareResult, EnergyResult, FitResult, SimulateResult, result_of

__all__ = [
    "CompareResult",
    "EnergyResult",
    "FitError",
    "FitResult",
    "SimulateResult",
    "campaign",
    "compare",
    "energy",
    "fit",
    "models",
    "plan",
    "run",
    "simulate",
]

_COMMANDS = ("simulate", "fit", "compare", "energy")


def simulate(oscillator, model, x0, t, v0=0.0, options=None):
    """One free vibration released at ``x0`` (and ``v0``), sampled at the times ``t``: a
    ``SimulateResult`` (report.json's keys, then ``t, x, v, a, force``, the energies, the
    internal states ``z1..zn`` and ``states``)."""
    return SimulateResult(*_native.simulate(oscillator, model, x0, t, v0, options))


def fit(oscillator, model, records, fit=None):
    """The model fitted to ``records``: a ``FitResult`` (report.json's structure plus the
    fitted series; ``result.params``, ``result.plot()``, ``result.export("c")``)."""
    return FitResult(*_native.fit(oscillator, model, records, fit))


def compare(oscillator, models, records, fit=None):
    """Several models fitted to the same records and ranked, with the law to use: a
    ``CompareResult`` (``result.recommended`` is that law's ``FitResult``; ``export`` writes
    it)."""
    return CompareResult(*_native.compare(oscillator, models, records, fit))


def energy(oscillator, records, model=None, options=None):
    """The energy-based friction force of every record (Eq. 7) against a reference (the
    model's force when a model is given, else a fitted Coulomb force): an
    ``EnergyResult``."""
    return EnergyResult(*_native.energy(oscillator, records, model, options))


def run(config_path, command="fit", out=None):
    """A configuration file run as ``frictionid <command>`` runs it: the result object the
    function of the same name returns (``models``: the listing). Nothing is written unless
    ``out`` names a folder (``plan``: report.json's dict); then the CLI's report folder (report.json, .md, .html, plots) is
    written there as ``frictionid <command> CONFIG --out OUT`` writes it."""
    native = _native.run(str(config_path), command, None if out is None else str(out))
    if command in _COMMANDS:
        return result_of(command, native)
    if command == "plan":
        return native[0]
    return native
