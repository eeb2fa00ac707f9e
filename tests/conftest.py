"""Shared fixtures: paths to the shared benchmark data (skip with a clear message when absent)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

_DEFAULT_SHARED = Path(__file__).resolve().parent.parent.parent / "shared"


def _shared_path() -> Path:
    return Path(os.environ.get("SBIB_SHARED") or _DEFAULT_SHARED)


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """The shared data directory (SBIB_SHARED or ../shared); skips the test when absent."""
    path = _shared_path()
    if not path.is_dir():
        pytest.skip(f"shared data not found at {path}; set SBIB_SHARED to run this test")
    return path


@pytest.fixture(scope="session")
def records_dir(shared_dir: Path) -> Path:
    """The benchmark's two-column record files (SBIB_RECORDS_DIR or <shared>/records/raw/FDZ)."""
    path = Path(os.environ.get("SBIB_RECORDS_DIR") or shared_dir / "records" / "raw" / "FDZ")
    if not path.is_dir():
        pytest.skip(f"benchmark records not found at {path}; set SBIB_RECORDS_DIR")
    return path
