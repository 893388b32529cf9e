import os
import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def hikari_bin():
    """The CLI to compare pixels with: $HIKARI_BIN, else the workspace's build."""
    for candidate in [os.environ.get("HIKARI_BIN"), ROOT / "target/release/hikari", ROOT / "target/debug/hikari"]:
        if candidate and pathlib.Path(candidate).is_file():
            return str(candidate)
    found = shutil.which("hikari")
    if found is None:
        pytest.fail("no hikari binary: build it (cargo build) or set HIKARI_BIN")
    return found
