"""Result objects: what ``fit``, ``compare``, ``simulate``, ``energy`` and ``run`` return.

Each result is the report's dict (report.json's structure plus numpy arrays for the series;
``result["parameters"]`` and every other key work as before) with:

- ``.params``: the parameters as a pandas DataFrame indexed by name (``value``,
  ``std_error``, ``ci_low``, ``ci_high``, ``unit``, ``status``);
- ``.report(format="text")``: the summary ``frictionid`` prints (``"markdown"``: report.md);
- ``.plot()``: a matplotlib Figure;
- ``_repr_html_``: the verdict and the parameter table, shown by notebooks.

pandas and matplotlib are imported only when ``.params`` or ``.plot()`` is used
(``pip install frictionid[notebook]`` installs both).
"""

import html
import importlib
import json
import math
import re

from . import _native

__all__ = ["CompareResult", "EnergyResult", "FitResult", "SimulateResult"]

#: The columns of ``.params``.
PARAM_COLUMNS = ["value", "std_error", "ci_low", "ci_high", "unit", "status"]

# Okabe-Ito colours (safe for colour-blind readers): a measured series blue (a broad light
# band under a fit), a fitted or model one vermillion, drawn over it.
MEASURED = "#0072B2"
MEASURED_BAND = "#56B4E9"
FITTED = "#D55E00"
REFERENCE = "#009E73"
# Of a plotted motion, the part kept after its last sample above this fraction of its peak.
MOTION_FRACTION = 0.02
MOTION_MARGIN = 0.1
STATUS_COLOURS = {"pass": "#009E73", "warn": "#E69F00", "fail": "#D55E00"}

# The keys of a fit that an export reads (the series stay behind).
_FIT_KEYS = ("command", "model", "model_parameters", "parameters", "oscillator", "compared")
_RECORD_KEYS = ("file", "max_speed")


def _optional(module, needed_by, package):
    """Imports `module`, or says which extra provides it when it is missing."""
    try:
        return importlib.import_module(module)
    except ImportError as e:  # pragma: no cover - the message is the point
        raise ImportError(
            f"frictionid: {needed_by} needs {package} (pip install 'frictionid[notebook]')"
        ) from e


def _pandas():
    return _optional("pandas", ".params", "pandas")


def _pyplot():
    return _optional("matplotlib.pyplot", ".plot()", "matplotlib")


def _rows_frame(rows):
    """``.params``' DataFrame of ``rows`` (name, value, std_error, ci_low, ci_high, unit,
    status)."""
    pd = _pandas()
    frame = pd.DataFrame(rows, columns=["parameter"] + PARAM_COLUMNS)
    return frame.set_index("parameter")


def _number(x):
    """``x`` as a float, ``nan`` for a missing value."""
    return math.nan if x is None else float(x)


def _fit_status(p):
    """The status column of the CLI's parameter table: fixed, fitted, or what bounds a
    parameter the records do not determine."""
    if not p.get("free", True):
        return "fixed"
    kind, bound = p.get("identifiability"), p.get("bound")
    if kind == "lower_bound" and bound is not None:
        return f"fitted, > {bound:.4g} at 95 %"
    if kind == "upper_bound" and bound is not None:
        return f"fitted, < {bound:.4g} at 95 %"
    if kind == "not_identifiable":
        return "fitted, not identifiable"
    return "fitted"


def _fit_rows(parameters):
    """``.params`` rows of a fit's ``parameters`` list."""
    rows = []
    for p in parameters:
        low, high = p.get("ci95") or (None, None)
        rows.append(
            (p["name"], _number(p.get("value")), _number(p.get("std_error")),
             _number(low), _number(high), p.get("unit", ""), _fit_status(p))
        )
    return rows


def _given_rows(model, axis="linear"):
    """``.params`` rows of a model dict's parameters (given, not fitted: no error)."""
    name = model.get("type")
    units = {}
    for m in _native.models(axis):
        if m["name"] == name:
            units = {p["name"]: p["unit"] for p in m["parameters"]}
    return [
        (k, _number(v), math.nan, math.nan, math.nan, units.get(k, ""), "given")
        for k, v in model.items()
        if k != "type" and isinstance(v, (int, float)) and not isinstance(v, bool)
    ]


def _motion_limit(t, series):
    """The time up to which any of ``series`` moves (its last sample above a small fraction
    of its peak), plus a margin; the record's end when nothing rests."""
    import numpy as np

    t = np.asarray(t, dtype=float)
    if t.size < 2:
        return None
    end = t[0]
    for y in series:
        y = np.abs(np.asarray(y, dtype=float))
        if y.size != t.size or not np.isfinite(y).any():
            continue
        peak = np.nanmax(y)
        moving = np.nonzero(y > MOTION_FRACTION * peak)[0] if peak > 0 else []
        if len(moving):
            end = max(end, t[moving[-1]])
    span = t[-1] - t[0]
    limit = end + MOTION_MARGIN * span
    return None if limit >= t[-1] else limit


def _html_table(headers, rows):
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>" for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _fmt(x):
    if isinstance(x, float):
        return "-" if math.isnan(x) else f"{x:.6g}"
    return x


def _fmt_error(x):
    return "-" if math.isnan(x) else f"{x:.2g}"


def _params_html(rows):
    return _html_table(
        ["parameter"] + PARAM_COLUMNS,
        [[name, _fmt(value), _fmt_error(se), _fmt(lo), _fmt(hi), unit, status]
         for name, value, se, lo, hi, unit, status in rows],
    )


def _inline_code(text):
    """``text`` escaped for HTML, its `code` spans as <code>."""
    return re.sub(r"`([^`]*)`", r"<code>\1</code>", html.escape(text))


def _verdict_html(status, text):
    colour = STATUS_COLOURS.get(status, "#555555")
    return (
        f'<p style="border-left: 4px solid {colour}; padding-left: 6px">'
        f"<b>{html.escape(status or '')}</b> {_inline_code(text)}</p>"
    )


class Result(dict):
    """A report's dict with its text forms; the base of every result object."""

    #: The command that made it, as the CLI names it.
    command = ""

    def __init__(self, report=(), texts=None):
        super().__init__(report)
        self._texts = dict(texts or {})

    def report(self, format="text"):
        """The report as text: ``"text"`` (the summary ``frictionid`` prints) or
        ``"markdown"`` (report.md)."""
        if format not in ("text", "markdown"):
            raise ValueError(f"report: format `{format}`: one of `text`, `markdown`")
        if format not in self._texts:
            raise ValueError(
                "report: this result was made from a dict alone; the text comes with the "
                "results that frictionid's functions return"
            )
        return self._texts[format]

    @property
    def verdict(self):
        """The verdict sentence (the CLI's), or ``None`` for a result without one."""
        return self._texts.get("verdict")

    @property
    def status(self):
        """The verdict's status (``pass``, ``warn`` or ``fail``), or ``None``."""
        return self._texts.get("status")

    def _param_rows(self):
        return []

    @property
    def params(self):
        """The parameters as a pandas DataFrame indexed by name: ``value``, ``std_error``,
        ``ci_low``, ``ci_high`` (the 95 % interval), ``unit``, ``status``."""
        return _rows_frame(self._param_rows())

    def _title(self):
        return f"frictionid {self.command}"

    def _html_body(self):
        return _params_html(self._param_rows())

    def _repr_html_(self):
        parts = [f"<div><b>{html.escape(self._title())}</b>"]
        if self.verdict:
            parts.append(_verdict_html(self.status, self.verdict))
        parts.append(self._html_body())
        parts.append("</div>")
        return "".join(parts)


def _for_export(fit):
    """The part of a fit's dict an export reads, as plain JSON values."""
    out = {k: fit[k] for k in _FIT_KEYS if k in fit}
    out["records"] = [
        {k: r[k] for k in _RECORD_KEYS if k in r} for r in fit.get("records", [])
    ]
    return out


class FitResult(Result):
    """A fit: report.json's dict with the fitted series of every record (``time``,
    ``measured``, ``fitted``, ...), ``.params``, ``.report()``, ``.plot()`` (measured against
    fitted) and ``export``."""

    command = "fit"

    def _param_rows(self):
        return _fit_rows(self.get("parameters", []))

    def _title(self):
        return f"frictionid fit: {self.get('model', '')}"

    def _html_body(self):
        rms = self.get("rms_residual")
        summary = ""
        if rms is not None:
            summary = (
                f"<p>rms {html.escape(str(self.get('compared', '')))} residual {rms:.4g} "
                f"{html.escape(str(self.get('residual_unit', '')))}, "
                f"{len(self.get('records', []))} record(s)</p>"
            )
        return _params_html(self._param_rows()) + summary

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

    def plot(self, residuals=False):
        """A matplotlib Figure: per record (one axes each), the measured and the fitted
        series against time, the time axis cut to the motion. ``residuals=True``: measured
        minus fitted instead."""
        plt = _pyplot()
        records = self.get("records", [])
        fig, axes = _figure(plt, len(records))
        for ax, record in zip(axes[:, 0], records):
            _plot_fit_records(ax, [record], _fit_ylabel(self, residuals), residuals)
            ax.set_title(record.get("file", ""), fontsize=9)
        what = "residuals" if residuals else "fitted"
        return _finish(fig, f"{self.get('model', '')} {what}", axes[0, 0])


def _fit_ylabel(fit, residuals):
    quantity = fit.get("compared", "measured")
    unit = fit.get("residual_unit", "")
    return f"{quantity} residual [{unit}]" if residuals else f"{quantity} [{unit}]"


def _plot_fit_records(ax, records, ylabel, residuals=False):
    """The measured and fitted series of ``records`` on ``ax`` (one legend entry per kind),
    or their residuals; the time axis cut to the motion."""
    shown_t, shown = [], []
    for record in records:
        t, measured, fitted = record.get("time"), record.get("measured"), record.get("fitted")
        if t is None or measured is None or fitted is None:
            continue
        hide = "_" if shown_t else ""
        if residuals:
            ax.plot(t, measured - fitted, color=MEASURED, lw=0.8, label=f"{hide}measured - fitted")
        else:
            ax.plot(t, measured, color=MEASURED_BAND, lw=3.0, label=f"{hide}measured")
            ax.plot(t, fitted, color=FITTED, lw=1.1, label=f"{hide}fitted")
        shown_t.append(t)
        shown.append([measured, fitted])
    _cut_to_motion(ax, shown_t, shown)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)


def _figure(plt, panels, height=2.3):
    """A figure of ``panels`` axes one above the other, room for a heading line on top."""
    n = max(panels, 1)
    return plt.subplots(n, 1, figsize=(7, height * n + 0.5), squeeze=False)


def _finish(fig, title, legend_from=None):
    """The title (left) and the legend (right, off the data) on one line above the axes,
    then the layout."""
    fig.suptitle(title, x=0.01, ha="left", fontsize=11)
    if legend_from is not None:
        handles, labels = legend_from.get_legend_handles_labels()
        if handles:
            fig.legend(handles, labels, loc="upper right", ncol=len(handles), frameon=False,
                       fontsize=9)
    # tight_layout leaves the title's line free, the legend sharing it.
    fig.tight_layout()
    return fig


def _cut_to_motion(ax, t, series):
    """The time axis of ``ax`` from the first sample to the end of the motion of ``series``
    (every record's), plus a margin."""
    import numpy as np

    starts = [np.asarray(x, dtype=float)[0] for x in t if len(x)]
    ends = []
    for times, ys in zip(t, series):
        limit = _motion_limit(times, ys)
        ends.append(times[-1] if limit is None else limit)
    if starts and ends:
        ax.set_xlim(min(starts), max(ends))


class CompareResult(FitResult):
    """A comparison: report.json's dict (``ranking``, ``verdict``, ...) with ``.recommended``
    (the law to use, a ``FitResult``), ``.results`` (every ranked law's ``FitResult`` by
    name), ``.ranking_table`` (a DataFrame), ``.params`` (the recommended law's) and
    ``.plot()`` (one panel per law, the recommended first)."""

    command = "compare"

    @property
    def results(self):
        """Every fitted law's ``FitResult``, by model name, in ranking order."""
        laws = self._texts.get("laws", {})
        return {
            f["model"]: FitResult(f, laws.get(f["model"])) for f in self.get("ranking", [])
        }

    @property
    def recommended(self):
        """The recommended law's ``FitResult`` (``None`` when the comparison names none)."""
        name = self.get("recommended")
        return self.results.get(name) if name else None

    def _shown(self):
        """The law whose parameters the result shows: the recommended one, else the best."""
        if self.recommended is not None:
            return self.recommended
        return next(iter(self.results.values()), FitResult())

    def _param_rows(self):
        return _fit_rows(self._shown().get("parameters", []))

    def _title(self):
        return f"frictionid compare: use {self.get('recommended') or '(none recommended)'}"

    @property
    def ranking_table(self):
        """The ranking as a DataFrame indexed by model: AIC, its difference to the best,
        BIC, the RMS and held-out RMS residuals, convergence, and which law is recommended."""
        pd = _pandas()
        return pd.DataFrame(
            self._ranking_rows(),
            columns=["model", "aic", "delta_aic", "bic", "rms_residual", "validation_rms",
                     "converged", "recommended"],
        ).set_index("model")

    def _ranking_rows(self):
        return [
            (f["model"], _number(f.get("aic")), _number(f.get("delta_aic")),
             _number(f.get("bic")), _number(f.get("rms_residual")),
             _number(f.get("validation_rms")), bool(f.get("converged")),
             f["model"] == self.get("recommended"))
            for f in self.get("ranking", [])
        ]

    def _html_body(self):
        shown = self._shown()
        ranking = _html_table(
            ["model", "AIC", "delta AIC", "BIC", "rms residual", "held-out rms", "converged",
             "recommended"],
            [[_fmt(c) for c in row] for row in self._ranking_rows()],
        )
        return (
            f"<p>parameters of <code>{html.escape(str(shown.get('model', '')))}</code></p>"
            + _params_html(self._param_rows())
            + "<p>ranking</p>"
            + ranking
        )

    def plot(self, model=None, residuals=False):
        """A matplotlib Figure. Without ``model``: one panel per law (the recommended first),
        each with every record's measured and fitted series (``residuals=True``: measured
        minus fitted, where laws differ). With ``model`` (a name, or ``"recommended"``):
        that law's fit, one panel per record."""
        if model is not None:
            name = self.get("recommended") if model == "recommended" else model
            if name not in self.results:
                raise ValueError(f"plot: no fitted law `{name}`; one of: {', '.join(self.results)}")
            return self.results[name].plot(residuals=residuals)
        plt = _pyplot()
        laws = list(self.results.values())
        recommended = self.get("recommended")
        laws.sort(key=lambda f: f.get("model") != recommended)
        fig, axes = _figure(plt, len(laws), height=2.1)
        for ax, law in zip(axes[:, 0], laws):
            _plot_fit_records(ax, law.get("records", []), _fit_ylabel(law, residuals), residuals)
            mark = " (recommended)" if law.get("model") == recommended else ""
            ax.set_title(f"{law.get('model')}{mark}", fontsize=9)
        if residuals:
            # One scale for every law, so that their residuals compare at a glance.
            low = min(ax.get_ylim()[0] for ax in axes[:, 0])
            high = max(ax.get_ylim()[1] for ax in axes[:, 0])
            for ax in axes[:, 0]:
                ax.set_ylim(low, high)
        title = f"compare: use {recommended}" if recommended else "compare: no law recommended"
        return _finish(fig, title, axes[0, 0])


def _axis_units(oscillator):
    """Displacement, velocity and force units on the oscillator's axis."""
    if (oscillator or {}).get("axis") == "rotary":
        return "rad", "rad/s", "N m"
    return "m", "m/s", "N"


def _axis_labels(oscillator):
    """The axis labels of displacement, velocity and friction on the oscillator's axis."""
    x, v, f = _axis_units(oscillator)
    if (oscillator or {}).get("axis") == "rotary":
        return f"angle [{x}]", f"angular velocity [{v}]", f"friction torque [{f}]"
    return f"x [{x}]", f"v [{v}]", f"friction force [{f}]"


class _GivenModelResult(Result):
    """A result of a model given, not fitted (a simulation, the energy analysis): its
    parameters are the given ones, on the oscillator's axis."""

    def _axis(self):
        return (self.get("oscillator") or {}).get("axis", "linear")

    def _param_rows(self):
        model = self.get("model")
        if isinstance(model, dict):
            return _given_rows(model, self._axis())
        return []


class SimulateResult(_GivenModelResult):
    """A simulation: report.json's dict with the trajectory (``t``, ``x``, ``v``, ``a``,
    ``force``, energies, states), ``.params`` (the model's given parameters), ``.report()``
    and ``.plot()`` (displacement, velocity and friction force against time)."""

    command = "simulate"

    def _title(self):
        model = self.get("model") or {}
        name = model.get("type", "") if isinstance(model, dict) else str(model)
        return f"frictionid simulate: {name}"

    def _html_body(self):
        facts = []
        for key, label, unit in [
            ("final_displacement", "final displacement", _axis_units(self.get("oscillator"))[0]),
            ("half_cycles", "half-cycles", ""),
            ("rest_time", "rest time", "s"),
        ]:
            if self.get(key) is not None:
                facts.append(f"{label} {_fmt(self[key])} {unit}".strip())
        return _params_html(self._param_rows()) + f"<p>{html.escape('; '.join(facts))}</p>"

    def plot(self):
        """A matplotlib Figure: displacement, velocity and friction force against time."""
        plt = _pyplot()
        labels = _axis_labels(self.get("oscillator"))
        fig, axes = _figure(plt, 3, height=2.0)
        axes = axes[:, 0]
        for ax, key, label in zip(axes, ("x", "v", "force"), labels):
            ax.plot(self["t"], self[key], color=MEASURED, lw=1.0)
            _cut_to_motion(ax, [self["t"]], [[self["v"]]])
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
        axes[-1].set_xlabel("time [s]")
        return _finish(fig, self._title())


class EnergyResult(_GivenModelResult):
    """The energy-based friction force (Eq. 7): report.json's dict with every record's
    series (``time``, ``friction``, ``model_force``, ...), ``.params`` (the reference
    model's parameters when one was given), ``.record_table`` (each record's mean force
    against the reference, a DataFrame), ``.report()`` and ``.plot()`` (the Eq. 7 force against time,
    one panel per record)."""

    command = "energy"

    def _record_rows(self):
        return [
            (r.get("file") or r.get("name") or f"record {i + 1}",
             _number(r.get("mean_abs_force")), _number(r.get("reference")),
             _number(r.get("percent_difference")), _number(r.get("half_cycle_mean")),
             _number(r.get("half_cycle_std")))
            for i, r in enumerate(self.get("records", []))
        ]

    @property
    def record_table(self):
        """Each record's energy-based force against the reference, a DataFrame indexed by
        record: ``mean_abs_force`` (Eq. 7), ``reference``, ``percent_difference``, and the
        half-cycles' mean force and its spread."""
        pd = _pandas()
        return pd.DataFrame(
            self._record_rows(),
            columns=["record", "mean_abs_force", "reference", "percent_difference",
                     "half_cycle_mean", "half_cycle_std"],
        ).set_index("record")

    def _html_body(self):
        table = _html_table(
            ["record", "mean |F| Eq. 7", "reference", "difference [%]", "half-cycle mean",
             "half-cycle std"],
            [[_fmt(c) for c in row] for row in self._record_rows()],
        )
        params = self._param_rows()
        return (_params_html(params) if params else "") + table

    def plot(self):
        """A matplotlib Figure: per record, the Eq. 7 force against time, the model's force
        drawn over it and the reference level."""
        import numpy as np

        plt = _pyplot()
        records = self.get("records", [])
        f_label = _axis_labels(self.get("oscillator"))[2]
        fig, axes = _figure(plt, len(records))
        for ax, r in zip(axes[:, 0], records):
            t = r["time"]
            ax.plot(t, r["friction"], color=MEASURED, lw=0.8, label="Eq. 7")
            series = [r["v"]] if "v" in r else []
            if "model_force" in r:
                # Where Eq. 7 is defined: at rest the model's force follows the noise's sign.
                model = np.where(np.isnan(r["friction"]), np.nan, r["model_force"])
                ax.plot(t, model, color=FITTED, lw=1.4, ls="--", zorder=3, label="model")
            if r.get("reference") is not None:
                ref = r["reference"]
                ax.axhline(ref, color=REFERENCE, lw=1.0, ls=":", label="reference")
                ax.axhline(-ref, color=REFERENCE, lw=1.0, ls=":")
            _cut_to_motion(ax, [t], [series])
            ax.set_title(r.get("file") or "", fontsize=9)
            ax.set_xlabel("time [s]")
            ax.set_ylabel(f_label)
            ax.grid(alpha=0.3)
        return _finish(fig, "energy-based friction force (Eq. 7)", axes[0, 0])


_BY_COMMAND = {
    "fit": FitResult,
    "compare": CompareResult,
    "simulate": SimulateResult,
    "energy": EnergyResult,
}


def result_of(command, native):
    """The result object of ``command`` from a native function's ``(dict, texts)``."""
    report, texts = native
    return _BY_COMMAND[command](report, texts)
