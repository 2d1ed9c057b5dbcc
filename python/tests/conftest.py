"""Shared fixtures: the repository, the `errp` program the package is
compared with, and one calibration session for the decoder tests."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def errp_bin() -> Path:
    """The `errp` program: $ERRP_BIN, or the repository's debug build."""
    p = Path(os.environ.get("ERRP_BIN", ROOT / "target" / "debug" / "errp"))
    if not p.exists():
        pytest.fail(
            f"the errp program is not at {p}: build it (cargo build) or set ERRP_BIN",
            pytrace=False,
        )
    return p


def cli(*args: str) -> str:
    """Runs `errp ARGS` from the repository and returns what it printed."""
    out = subprocess.run(
        [str(errp_bin()), *args], cwd=ROOT, capture_output=True, text=True, timeout=1800
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def session():
    """The calibration session of `errp calibrate --accuracy 0.7438 --seed 1`."""
    import errp

    return errp.simulate_session(accuracy=0.7438, seed=1)
