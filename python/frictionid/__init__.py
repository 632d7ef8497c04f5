"""frictionid: identify friction models from the free vibration of an oscillator.

The functions take the configuration's tables as dicts (``oscillator``, ``model``, ``fit``,
``energy``) and records as dicts of arrays, call the same engine as the ``frictionid``
command line, and return the same structure as its report.json, with numpy arrays for the
series. Units are SI (m, s, kg, N). The ``oscillator`` dict may give one standard deviation
of each property (``mass_std``, ``damping_std``, ``stiffness_std``, ``normal_force_std``):
every fitted parameter then reports ``std_error_components`` and a total ``std_error``.

- ``models()``: every registered model (``frictionid models --json``).
- ``simulate(oscillator, model, x0, t, v0=0.0, options=None)``: one free vibration.
- ``fit(oscillator, model, records, fit=None)``: a model fitted to records.
- ``compare(oscillator, models, records, fit=None)``: several models ranked by AIC.
- ``energy(oscillator, records, model=None, options=None)``: the energy-based force (Eq. 7).
- ``run(config_path, command="fit", out=None)``: a configuration file, as the CLI runs it.
- ``campaign(config, manifest=None, executor=None, out=None)``: every group of a campaign
  (one task per group on any ``concurrent.futures`` executor), campaign.csv as a pandas
  DataFrame (pandas: ``pip install frictionid[campaign]``).

Bad input raises ``ValueError``; a fit that failed raises ``FitError``. Ctrl-C stops a fit.
"""

from ._native import FitError, compare, energy, fit, models, run, simulate
from .campaign import campaign

__all__ = ["FitError", "campaign", "compare", "energy", "fit", "models", "run", "simulate"]
