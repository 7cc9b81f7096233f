"""Shared fixtures: the CLI binary the package must agree with, and the data folders.

The runner (crates/cli/tests/suite/python.rs) sets SPECULA_BIN to the `specula` it built; the
shared data folder and the Debian data packages are where .ci/run puts them.
"""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[3]
SHARED = REPOSITORY.parent / "shared"


def required(what: str, why: str):
    """Skips locally, fails under CI=true: a missing tool is a broken CI machine."""
    message = f"{what} is missing: {why}"
    if os.environ.get("CI") == "true":
        pytest.fail(message)
    pytest.skip(message)


@pytest.fixture(scope="session")
def cli():
    """Runs the `specula` command; returns (exit code, stdout, stderr)."""
    binary = os.environ.get("SPECULA_BIN") or shutil.which("specula")
    if not binary:
        required("the specula binary", "set SPECULA_BIN (crates/cli/tests/suite/python.rs does)")

    def run(*args: str):
        done = subprocess.run(
            [binary, *args], capture_output=True, text=True, timeout=600, check=False
        )
        return done.returncode, done.stdout, done.stderr

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    """Runs the `specula` command and parses its JSON output."""

    def run(*args: str):
        code, out, err = cli(*args)
        assert code == 0, err
        return json.loads(out)

    return run


@pytest.fixture(scope="session")
def mri():
    """MRIcron's ch2.nii.gz: Colin27's T1 with skull (Debian's mricron-data)."""
    path = Path("/usr/share/mricron/templates/ch2.nii.gz")
    if not path.exists():
        required(str(path), "install Debian's mricron-data")
    return path
