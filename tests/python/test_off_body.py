"""Issue 53: grids off their body raise terrain.Error naming the bad value, from a file (the
PDS3 label's key) and from an array (the geotransform), as the command line refuses them."""

import re

import numpy as np
import pytest

import terrain
from conftest import SAMPLES

MOON_EQC = "+proj=eqc +lat_ts=0 +lat_0=0 +lon_0=180 +R=1737400 +units=m +no_defs +type=crs"


def vesta_tile(tmp_path, edits):
    """The Vesta sample's label cut to a 64 x 64 tile, beside an image made here."""
    rows, cols = np.mgrid[0:64, 0:64]
    dn = (300 * np.sin(cols / 5.0) * np.cos(rows / 7.0) + 40 * ((rows * cols) % 5)).astype(">i2")
    (tmp_path / "tile64.img").write_bytes(dn.tobytes())
    label = (SAMPLES / "vesta_hamo_tile.lbl").read_text()
    edits = {"RECORD_BYTES": "128", "FILE_RECORDS": "64", r"\^IMAGE": '"tile64.img"',
             "LINES": "64", "LINE_SAMPLES": "64", "LINE_LAST_PIXEL": "64",
             "SAMPLE_LAST_PIXEL": "64", "SAMPLE_PROJECTION_OFFSET": "31.5 <PIXEL>", **edits}
    for key, value in edits.items():
        label, n = re.subn(r"(?m)^(\s*" + key + r")\s*=.*$", lambda m: m.group(1) + " = " + value,
                           label, count=1)
        assert n == 1, key
    path = tmp_path / "tile.lbl"
    path.write_text(label)
    return str(path)


def test_label_radius_without_unit(tmp_path):
    good = vesta_tile(tmp_path, {})
    assert terrain.segment(good).labels.shape == (64, 64)
    bad = vesta_tile(tmp_path, {"A_AXIS_RADIUS": "1.5"})
    with pytest.raises(terrain.Error, match=r"^read: .*A_AXIS_RADIUS = 1\.5.*not a surface$"):
        terrain.segment(bad)


def test_array_off_the_moon():
    z = np.add.outer(np.sin(np.arange(32) / 3.0), np.cos(np.arange(48) / 4.0)) * 100
    on = (0.0, 7580.84, 0.0, 667113.92, 0.0, -7580.84)
    assert terrain.segment(z, on, MOON_EQC).labels.shape == (32, 48)
    off = (0.0, 7580.84, 0.0, 1e7, 0.0, -7580.84)
    with pytest.raises(terrain.Error, match=r"^read: .*geotransform's y origin.*not a surface$"):
        terrain.segment(z, off, MOON_EQC)
    # Heights through the centre of the Moon.
    with pytest.raises(terrain.Error, match="must stay positive"):
        terrain.segment(z - 2e6, on, MOON_EQC)
