"""Campaigns from Python: every group of a manifest fitted as ``frictionid campaign`` fits
it, on this machine or on any ``concurrent.futures.Executor`` (a process pool, a Dask
cluster's ``client.get_executor()``, Ray's). Each group is one task: strings in (the
configuration's text, the ``[campaign]`` table and the group as JSON), a JSON string out; no
engine object crosses the wire. The workers must see the record files at the paths the
manifest gives (relative to the configuration file)."""

import io

from . import _native


def run_group(config_path, config_text, campaign, task):
    """One group's fit (the task an executor runs): its result as JSON text."""
    return _native.campaign_group(config_path, config_text, campaign, task)


def campaign(config, manifest=None, executor=None, out=None):
    """Fits every group of the campaign of ``config`` (a TOML file with a ``[campaign]``
    table, or any config with ``manifest`` given, a CSV path relative to the working
    directory) and returns campaign.csv's rows as a pandas DataFrame.

    ``executor``: a ``concurrent.futures.Executor`` that runs one task per group (default:
    the groups one after the other here, each fit using every core). ``out``: a directory
    where campaign.csv, the trend plots and report.json/md/html are written.
    """
    import pandas as pd

    config = str(config)
    manifest = None if manifest is None else str(manifest)
    text, table, tasks = _native.campaign_plan(config, manifest)
    if executor is None:
        results = [run_group(config, text, table, task) for task in tasks]
    else:
        futures = [executor.submit(run_group, config, text, table, task) for task in tasks]
        results = [f.result() for f in futures]
    csv = _native.campaign_assemble(config, results, manifest, None if out is None else str(out))
    return pd.read_csv(io.StringIO(csv), keep_default_na=False, na_values=[""])
