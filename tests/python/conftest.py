"""Fixtures of the Python tests: the samples, the built `terrain` command line, scratch dirs.

ctest runs these with PYTHONPATH=<build>/python and TERRAIN_CLI=<the built terrain>."""

import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
SAMPLES = SOURCE_DIR / "examples" / "data"
SAMPLE_FILES = {
    "vesta": SAMPLES / "vesta_hamo_tile.lbl",
    "moon4c": SAMPLES / "moon_ldem4_copernicus.tif",
    "moon1g": SAMPLES / "moon_ldem1_global.tif",
    "marsc": SAMPLES / "mars_hirise_crop.tif",
}


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("TERRAIN_CLI")
    assert path and os.access(path, os.X_OK), "TERRAIN_CLI must name the built terrain program"

    def run(*args):
        return subprocess.run([path, *map(str, args)], capture_output=True, text=True)

    return run


@pytest.fixture(scope="session")
def moon():
    return str(SAMPLE_FILES["moon4c"])
