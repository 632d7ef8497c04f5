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
- ``plan(oscillator, model, plan, records=None, fit=None)``: which records to take next
  (``frictionid plan``; ``plan`` is the ``[plan]`` table).
- ``run(config_path, command="fit", out=None)``: a configuration file, as the CLI runs it.
- ``campaign(config, manifest=None, executor=None, out=None)``: every group of a campaign
  (one task per group on any ``concurrent.futures`` executor), campaign.csv as a pandas
  DataFrame (pandas: ``pip install frictionid[campaign]``).

``fit``, ``compare`` and ``run`` (for ``fit`` and ``compare``) return a ``FitResult``: the
report's dict with ``export(lang="c", prefix="fid_", normal_force=None)``, the fitted law (a
comparison's recommended one) as C, Rust or Python source text, or ``lang="table"`` for the
steady-state compensation table (``frictionid export``).

Bad input raises ``ValueError``; a fit that failed raises ``FitError``. Ctrl-C stops a fit.
"""

import json

from . import _native
from ._native import FitError, energy, models, plan, simulate
from .campaign import campaign

__all__ = [
    "FitError",
    "FitResult",
    "campaign",
    "compare",
    "energy",
    "fit",
    "models",
    "plan",
    "run",
    "simulate",
]

# The keys of a fit that an export reads (the series stay behind).
_FIT_KEYS = ("command", "model", "model_parameters", "parameters", "oscillator", "compared")
_RECORD_KEYS = ("file", "max_speed")


def _for_export(fit):
    """The part of a fit's dict an export reads, as plain JSON values."""
    out = {k: fit[k] for k in _FIT_KEYS if k in fit}
    out["records"] = [
        {k: r[k] for k in _RECORD_KEYS if k in r} for r in fit.get("records", [])
    ]
    return out


class FitResult(dict):
    """A fit's (or a comparison's) report as a dict, with ``export``."""

    def export(self, lang="c", prefix="fid_", normal_force=None):
        """The fitted law (a comparison's recommended one) as source text: ``lang`` one of
        ``"c"``, ``"rust"``, ``"python"`` or ``"table"`` (the steady-state force on a velocity
        grid, as CSV). ``prefix`` names the C identifiers; ``normal_force`` [N] is the
        table's (default: the fit's)."""
        if "ranking" in self:
            report = {
                "command": "compare",
                "verdict": self.get("verdict"),
                "ranking": [_for_export(f) for f in self["ranking"]],
            }
        else:
            report = _for_export(self)
        return _native.export(json.dumps(report), lang, prefix, normal_force)


def fit(oscillator, model, records, fit=None):
    """The model fitted to ``records``: report.json's structure plus the fitted series, as a
    ``FitResult`` (``result.export("c")`` writes the fitted law as C)."""
    return FitResult(_native.fit(oscillator, model, records, fit))


def compare(oscillator, models, records, fit=None):
    """Several models ranked by AIC, as a ``FitResult`` (its ``export`` writes the
    recommended law)."""
    return FitResult(_native.compare(oscillator, models, records, fit))


def run(config_path, command="fit", out=None):
    """A configuration file run as ``frictionid <command>`` runs it; its report.json (a
    ``FitResult`` for ``fit`` and ``compare``)."""
    report = _native.run(config_path, command, out)
    if command in ("fit", "compare") and isinstance(report, dict):
        return FitResult(report)
    return report
