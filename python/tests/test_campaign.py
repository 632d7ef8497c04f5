"""frictionid.campaign: the fixture campaign (the three FMM records, Coulomb truth
mu = 0.24) run here, on a process pool and, when dask.distributed is installed, on a Dask
LocalCluster with worker processes; every route must write the same campaign.csv as the
``frictionid campaign`` binary (when .ci/run names it)."""

import os
import subprocess
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

import frictionid

pd = pytest.importorskip("pandas")

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "fixtures" / "campaign" / "campaign.toml"


def test_each_group_recovers_the_truth_and_a_process_pool_gives_the_same_table(tmp_path):
    here = frictionid.campaign(CONFIG, out=tmp_path / "here")
    assert list(here["model"]) == ["coulomb"] * 3
    assert list(here["verdict"]) == ["ok"] * 3
    assert (abs(here["mu"] - 0.24) < 1e-3).all()
    assert list(here["amplitude_mm"]) == [10, 14, 22]
    with ProcessPoolExecutor(max_workers=2) as pool:
        pooled = frictionid.campaign(CONFIG, executor=pool, out=tmp_path / "pool")
    pd.testing.assert_frame_equal(here, pooled)
    csv = (tmp_path / "here" / "campaign.csv").read_text()
    assert (tmp_path / "pool" / "campaign.csv").read_text() == csv
    binary = os.environ.get("FRICTIONID_BIN")
    if binary:
        subprocess.run([binary, "campaign", CONFIG, "--quiet", "--out", tmp_path / "bin"], check=True)
        assert (tmp_path / "bin" / "campaign.csv").read_text() == csv


def test_a_dask_local_cluster_gives_the_same_table(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        with distributed.Client(cluster) as client:
            on_dask = frictionid.campaign(CONFIG, executor=client.get_executor(), out=tmp_path / "dask")
    here = frictionid.campaign(CONFIG, out=tmp_path / "here")
    pd.testing.assert_frame_equal(here, on_dask)
    assert (tmp_path / "dask" / "campaign.csv").read_text() == (tmp_path / "here" / "campaign.csv").read_text()


def test_a_manifest_given_here_replaces_the_configs(tmp_path):
    manifest = tmp_path / "one.csv"
    manifest.write_text(f"file,x0,load\n{ROOT / 'fixtures' / 'x14mm.csv'},0.014,heavy\n")
    table = frictionid.campaign(CONFIG, manifest=manifest)
    assert list(table["load"]) == ["heavy"]
    assert abs(table["mu"][0] - 0.24) < 1e-3


def test_a_bad_manifest_raises_value_error_naming_line_and_column(tmp_path):
    manifest = tmp_path / "bad.csv"
    manifest.write_text("file,x0\na.csv,ten\n")
    with pytest.raises(ValueError, match="bad.csv:2: column `x0`: cannot use `ten`"):
        frictionid.campaign(CONFIG, manifest=manifest)
