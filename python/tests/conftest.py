"""Where the shared datasets and the `gaitclip` binary are, for the tests of the wheel.

The datasets sit at ../shared/datasets beside the project: a test that needs them is skipped
with the reason when they are absent, and fails in CI (CI=true), as the Rust tests do. The
`gaitclip` binary the Rust tests built is named by the GAITCLIP environment variable (as the
Bluetooth tests take it); tests that compare with it are skipped without it, and fail in CI.
"""

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATASETS = ROOT.parent / "shared" / "datasets"


def need(what: str, present: bool) -> None:
    if present:
        return
    if os.environ.get("CI") == "true":
        pytest.fail(f"{what} is absent (and CI=true)")
    pytest.skip(f"SKIPPED: {what} is absent")


@pytest.fixture(scope="session")
def datasets() -> pathlib.Path:
    need(f"{DATASETS}", DATASETS.is_dir())
    return DATASETS


@pytest.fixture(scope="session")
def gaitclip_cli() -> str:
    path = os.environ.get("GAITCLIP", "")
    need("the gaitclip binary (GAITCLIP)", bool(path) and os.path.exists(path))
    return path
