"""The QGIS Processing provider (qgis/terrain_provider) run headless by qgis_process.

ctest runs this with QGIS_PROCESS=<qgis_process.bin> (Debian's qgis_process wrapper adds an
option the program refuses), TERRAIN_PYTHONPATH=<build>/python and TERRAIN_CLI. The plugin is
copied into a fresh QGIS profile (QGIS_CUSTOM_CONFIG_PATH) and enabled there."""

import json
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest
from osgeo import gdal

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
VESTA = SOURCE_DIR / "examples" / "data" / "vesta_hamo_tile.lbl"
MOON = SOURCE_DIR / "examples" / "data" / "moon_ldem4_copernicus.tif"

gdal.UseExceptions()


@pytest.fixture(scope="module")
def qgis(tmp_path_factory):
    program = os.environ["QGIS_PROCESS"]
    root = tmp_path_factory.mktemp("qgis")
    plugins = root / "config" / "profiles" / "default" / "python" / "plugins"
    shutil.copytree(SOURCE_DIR / "qgis" / "terrain_provider", plugins / "terrain_provider")
    # GDAL_PAM_ENABLED=NO: no .aux.xml beside the samples when QGIS reads their statistics.
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", QGIS_CUSTOM_CONFIG_PATH=str(root / "config"),
               GDAL_PAM_ENABLED="NO",
               XDG_RUNTIME_DIR=str(root / "runtime"))
    (root / "runtime").mkdir(mode=0o700)
    enabled = subprocess.run([program, "plugins", "enable", "terrain_provider"], env=env,
                             capture_output=True, text=True, timeout=300)
    assert enabled.returncode == 0, enabled.stderr

    def run(algorithm, backend="module", **parameters):
        e = dict(env)
        if backend == "cli":
            e["TERRAIN_BACKEND"] = "cli"
        args = [program, "--json", "run", algorithm, "--"]
        args += [f"{k}={v}" for k, v in parameters.items()]
        done = subprocess.run(args, env=e, capture_output=True, text=True, timeout=600)
        results = None
        if done.returncode == 0:
            # The JSON document is the last part of stdout (warnings may come before it).
            results = json.loads(done.stdout[done.stdout.index("{"):])["results"]
        return done, results

    run.env = env
    return run


@pytest.fixture(scope="module")
def cli_vesta(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "vesta"
    done = subprocess.run([os.environ["TERRAIN_CLI"], "segment", str(VESTA), "-o", str(out), "-q"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out, int(done.stdout.split(": ", 1)[1].split()[0])


def test_the_provider_lists_its_algorithms(qgis):
    done = subprocess.run([os.environ["QGIS_PROCESS"], "list"], env=qgis.env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    for line in ("terrain:segment\tSegment DEM into landform regions",
                 "terrain:sweep\tMulti-scale sweep", "terrain:shapeindex\tShape index"):
        assert line in done.stdout


@pytest.mark.parametrize("backend", ["module", "cli"])
def test_segment_on_vesta(qgis, cli_vesta, tmp_path, backend):
    reference, regions = cli_vesta
    out = tmp_path / "out"
    done, results = qgis("terrain:segment", backend=backend, INPUT=VESTA, OUTPUT=out)
    assert done.returncode == 0, done.stdout + done.stderr
    assert results["REGION_COUNT"] == regions
    assert pathlib.Path(results["LABELS"]) == out / "labels.tif"
    for name in ("labels.tif", "regions.geojson", "adjacency.json", "adjacency.graphml"):
        assert (out / name).read_bytes() == (reference / name).read_bytes(), name
    run = json.loads((out / "run.json").read_text())
    assert run["counts"]["regions"] == regions
    assert run["parameters"]["persistence"] == 10


def test_segment_parameters_reach_terrain(qgis, tmp_path):
    out = tmp_path / "out"
    # SCALE 1: the single scale of the options given (0, the default, is the landforms').
    done, results = qgis("terrain:segment", INPUT=MOON, OUTPUT=out, SCALE=1, PERSISTENCE=5,
                         AREA_RATIO=1, COST=2, RINGS=3)
    assert done.returncode == 0, done.stdout + done.stderr
    parameters = json.loads((out / "run.json").read_text())["parameters"]
    assert parameters["persistence"] == 5 and parameters["area_ratio_percent"] == 1
    assert parameters["cost"] == "standard" and parameters["rings"] == 3
    labels = gdal.Open(str(out / "labels.tif")).ReadAsArray()
    assert int(labels.max()) == results["REGION_COUNT"]


def test_segment_at_a_radius(qgis, tmp_path):
    # RADIUS and WINDOW reach the library from both back ends, which give the same labels.
    labels = {}
    for backend in ("module", "cli"):
        out = tmp_path / backend
        done, _ = qgis("terrain:segment", backend=backend, INPUT=MOON, OUTPUT=out, SCALE=1,
                       RADIUS=30000, WINDOW=1)
        assert done.returncode == 0, done.stdout + done.stderr
        parameters = json.loads((out / "run.json").read_text())["parameters"]
        assert parameters["radius"] == 30000 and parameters["shape_index_window"] == "ball"
        ds = gdal.Open(str(out / "labels.tif"))
        labels[backend] = ds.ReadAsArray()
    assert np.array_equal(labels["module"], labels["cli"])


def test_segment_with_the_radius_chosen_per_pixel(qgis, tmp_path):
    # AUTO_RADIUS with a single area ratio: the command line's --radius auto --area-ratio 1.
    out = tmp_path / "auto"
    done, _ = qgis("terrain:segment", INPUT=MOON, OUTPUT=out, SCALE=1, AUTO_RADIUS=True,
                   AREA_RATIO=1)
    assert done.returncode == 0, done.stdout + done.stderr
    parameters = json.loads((out / "run.json").read_text())["parameters"]
    assert parameters["radius"] == "auto" and parameters["area_ratio_percent"] == 1
    assert len(parameters["radii_m"]) >= 2


def test_library_errors_reach_qgis(qgis, tmp_path):
    done, _ = qgis("terrain:sweep", INPUT=MOON, OUTPUT=tmp_path / "s", AREA_RATIOS="0.5,200")
    assert done.returncode != 0
    assert "--area-ratios takes percentages in (0, 100]" in done.stdout + done.stderr


def test_sweep_and_shape_index(qgis, tmp_path):
    done, results = qgis("terrain:sweep", INPUT=MOON, OUTPUT=tmp_path / "s", AREA_RATIOS="0.5,1")
    assert done.returncode == 0, done.stdout + done.stderr
    labels = gdal.Open(results["LABELS"])
    assert labels.RasterCount == 2
    assert (tmp_path / "s" / "lineage.json").exists()
    out = tmp_path / "si.tif"
    done, results = qgis("terrain:shapeindex", INPUT=MOON, OUTPUT=out)
    assert done.returncode == 0, done.stdout + done.stderr
    si = gdal.Open(str(out)).ReadAsArray()
    valid = np.isfinite(si)
    assert valid.mean() > 0.9 and si[valid].min() >= 0 and si[valid].max() <= 100
    done, _ = qgis("terrain:shapeindex", backend="cli", INPUT=MOON, OUTPUT=tmp_path / "si2.tif")
    assert done.returncode == 0, done.stdout + done.stderr
    si2 = gdal.Open(str(tmp_path / "si2.tif")).ReadAsArray()
    assert np.allclose(si2[valid], si[valid], atol=1e-4)


def test_shape_index_window(qgis, tmp_path):
    # RADIUS on the ground (WINDOW 0, disk, the default) or in 3-D (WINDOW 1, ball); the
    # module and the command line give the same values for each.
    values = {}
    for window in (0, 1):
        for backend in ("module", "cli"):
            out = tmp_path / f"si_{window}_{backend}.tif"
            done, _ = qgis("terrain:shapeindex", backend=backend, INPUT=MOON, RADIUS=30000,
                           WINDOW=window, OUTPUT=out)
            assert done.returncode == 0, done.stdout + done.stderr
            ds = gdal.Open(str(out))
            values[window, backend] = ds.ReadAsArray()
    cli = subprocess.run([os.environ["TERRAIN_CLI"], "field", str(MOON), "--radius", "30000",
                          "-o", str(tmp_path / "disk.tif"), "-q"], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    ds = gdal.Open(str(tmp_path / "disk.tif"))
    default = ds.ReadAsArray()
    valid = np.isfinite(default)
    for window in (0, 1):
        assert np.allclose(values[window, "module"][valid], values[window, "cli"][valid],
                           atol=1e-4)
    assert np.allclose(values[0, "cli"][valid], default[valid], atol=1e-4)
    assert not np.allclose(values[1, "cli"][valid], default[valid], atol=1e-4)
