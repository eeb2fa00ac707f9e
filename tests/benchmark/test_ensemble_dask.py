"""The same ensemble on a Dask LocalCluster gives the local results bit for bit."""

from __future__ import annotations

import pytest

from benchmark.applications.ensemble import EnsembleConfig, read_ensemble, run_ensemble

distributed = pytest.importorskip("distributed")

TOML = """
run = "probe"
base_seed = 3
controllers = ["a", "b"]
records = ["kobe"]
pga = [1.0, 3.0]
[synthetic]
templates = ["elcentro"]
realisations = 3
[grid]
"damper.scale" = [0.5, 1.5]
"""


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        yield cluster


def test_local_cluster_matches_local_processes(tmp_path, cluster):
    cfg = tmp_path / "d.toml"
    cfg.write_text(TOML)
    config = EnsembleConfig.from_toml(cfg)
    local = run_ensemble(config, tmp_path / "local.h5", jobs=1, progress=False)
    remote = run_ensemble(config, tmp_path / "dask.h5", scheduler=cluster.scheduler_address, progress=False)
    assert local.complete and remote.complete and remote.workers.startswith("dask:")
    a, b = read_ensemble(tmp_path / "local.h5"), read_ensemble(tmp_path / "dask.h5")
    assert list(a.cases["key"]) == list(b.cases["key"])
    for name in a.results:
        assert a.results[name].tobytes() == b.results[name].tobytes(), name


def test_dask_ensemble_resumes_a_local_one(tmp_path, cluster):
    cfg = tmp_path / "d.toml"
    cfg.write_text(TOML)
    config = EnsembleConfig.from_toml(cfg)
    run_ensemble(config, tmp_path / "mix.h5", jobs=1, progress=False, max_cases=7)
    with distributed.Client(cluster) as client:
        s = run_ensemble(config, tmp_path / "mix.h5", client=client, progress=False)
    assert s.n_resumed == 7 and s.complete
    run_ensemble(config, tmp_path / "ref.h5", jobs=1, progress=False)
    a, b = read_ensemble(tmp_path / "mix.h5"), read_ensemble(tmp_path / "ref.h5")
    for name in a.results:
        assert a.results[name].tobytes() == b.results[name].tobytes(), name


def test_unreachable_scheduler_is_an_input_error(tmp_path, monkeypatch):
    import benchmark.applications.ensemble
    from benchmark.foundation.errors import InputError

    monkeypatch.setattr(benchmark.applications.ensemble, "DASK_CONNECT_TIMEOUT_S", 2.0)
    cfg = tmp_path / "d.toml"
    cfg.write_text('run = "probe"\ncontrollers = ["a"]\nrecords = ["kobe"]\n')
    config = EnsembleConfig.from_toml(cfg)
    with pytest.raises(InputError, match="Dask scheduler"):
        run_ensemble(config, tmp_path / "x.h5", scheduler="tcp://127.0.0.1:1", progress=False)
