"""Shared fixtures: the repository, the `errp` program the package is
compared with, and one calibration session for the decoder tests."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def errp_bin() -> Path:
    """The `errp` program the package is compared with: $ERRP_BIN, else the
    repository's debug or release build. A test that needs it is skipped,
    with the command that builds it, when there is none (a set ERRP_BIN
    that names no file is an error)."""
    given = os.environ.get("ERRP_BIN")
    if given:
        if not Path(given).is_file():
            pytest.fail(f"ERRP_BIN={given}: no such file", pytrace=False)
        return Path(given)
    for profile in ("debug", "release"):
        p = ROOT / "target" / profile / "errp"
        if p.is_file():
            return p
    pytest.skip(
        "compares with the errp program, which is not built: run `cargo build` in "
        f"{ROOT} (or set ERRP_BIN to an errp program)"
    )


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
