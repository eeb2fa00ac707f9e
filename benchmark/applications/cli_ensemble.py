"""``sbib ensemble``: records × controllers × parameter grids × synthetic seeds, resumable."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from benchmark.applications.ensemble import EnsembleConfig, building_notes, run_ensemble
from benchmark.foundation.arguments import positive_int
from benchmark.foundation.atomic import output_file_of

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``ensemble`` sub-command to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """
    p = subparsers.add_parser(
        "ensemble", help="run an ensemble (records x controllers x grids x seeds) into one HDF5 file",
        description="Run the cases of an ensemble described in a TOML file (see examples/ensemble.toml) "
                    "on local processes or a Dask cluster, streaming finished runs into a journal and "
                    "one HDF5 file. Re-running the same command after an interruption (Ctrl-C, kill) "
                    "runs only the unfinished cases.")
    p.add_argument("--config", required=True, help="ensemble description (TOML)")
    p.add_argument("--out", default=None, type=output_file_of("hdf5"),
                   help="HDF5 results file (default: <config stem>.h5 beside the config); "
                        "its journal is <out>.journal")
    p.add_argument("--jobs", type=positive_int, default=None,
                   help="local worker processes (default: all cores; 1 runs in this process)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="Dask scheduler address (tcp://host:8786); needs the 'dask' extra")
    p.add_argument("--run", default=None,
                   help="override the config's run function ('simulation', 'probe' or module:function)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    config = EnsembleConfig.from_toml(args.config)
    out = Path(args.out) if args.out else Path(args.config).with_suffix(".h5")
    jobs = args.jobs if args.jobs is not None else (os.cpu_count() or 1)
    for note in building_notes(config.building):  # the damper models' notes, as sbib run prints them
        print(f"sbib ensemble: {note if note.startswith('warning: ') else 'note: ' + note}", file=sys.stderr,
              flush=True)
    summary = run_ensemble(config, out, jobs=jobs, scheduler=args.scheduler, run=args.run,
                           progress=not args.no_progress)
    for note in _motion_notes(summary.path):  # devices beyond a model's fitted motion, as sbib run says
        print(f"sbib ensemble: {note}", file=sys.stderr, flush=True)
    print(json.dumps(summary.as_dict(), indent=2))
    return 0


def _motion_notes(path: Path) -> list[str]:
    """The ``motion_notes`` the ensemble's file holds (written by ``write_hdf5``)."""
    import h5py

    with h5py.File(path, "r") as f:
        text = f.attrs.get("motion_notes")
    return list(json.loads(text)) if text else []
