"""The add-on's tests run in Blender's Python (PyPI bpy 5.x, CPython 3.13):
`bash scripts/blender.sh test`, which builds the add-on's zip and names it
in $HIKARI_BLENDER_ZIP. The session installs that zip as Blender's
"Install from Disk" does (into a throwaway user folder: $HOME is the test
run's own), so the add-on and hikari_render come from the zip and its
wheel. Without $HIKARI_BLENDER_ZIP the add-on is registered from the
source tree (blender/) and hikari_render must be installed beside bpy."""

import importlib
import os
import pathlib
import sys

import pytest

BLENDER = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BLENDER / "tests"))


def install_zip(path: str):
    """The add-on installed from `path` and enabled: its module."""
    import bpy

    result = bpy.ops.extensions.package_install_files(filepath=path, repo="user_default", enable_on_install=True)
    assert result == {"FINISHED"}, result
    module = importlib.import_module("bl_ext.user_default.hikari_blender")
    import hikari_render

    # The wheel inside the zip, not one installed beside bpy.
    assert "extensions" in hikari_render.__file__, hikari_render.__file__
    return module


@pytest.fixture(scope="session")
def addon():
    zip_path = os.environ.get("HIKARI_BLENDER_ZIP")
    if zip_path:
        yield install_zip(zip_path)
        return
    sys.path.insert(0, str(BLENDER))
    import hikari_blender

    hikari_blender.register()
    yield hikari_blender
    hikari_blender.unregister()
