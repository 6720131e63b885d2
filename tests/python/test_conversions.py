"""GeoDataFrame and networkx conversions, sweep, shape index and Reeb graph."""

import numpy as np
import pytest

import terrain


@pytest.fixture(scope="module")
def result(moon):
    return terrain.segment(moon)


def test_geodataframe(result):
    import geopandas as gpd  # installed by the set-up: a missing client fails
    gdf = result.to_geodataframe()
    assert isinstance(gdf, gpd.GeoDataFrame)
    assert len(gdf) == result.region_count
    assert list(gdf["id"]) == list(result.regions["id"])
    assert np.allclose(gdf["area_m2"], result.regions["area_m2"])
    assert gdf.crs is not None and "MOON" in gdf.crs.to_wkt().upper()
    assert (gdf.geometry.area > 0).all()
    # Polygons cover the labelled pixels: total polygon area = labelled pixels x pixel area.
    gt = result.dem.geotransform
    pixels = np.count_nonzero(result.labels)
    assert gdf.geometry.area.sum() == pytest.approx(pixels * abs(gt[1] * gt[5]), rel=1e-9)


def test_networkx(result):
    import networkx as nx  # installed by the set-up: a missing client fails
    g = result.graph.to_networkx()
    assert g.number_of_nodes() == result.region_count
    assert g.number_of_edges() == len(result.graph.edges["a"])
    degrees = dict(g.degree())
    for rid, count in zip(result.regions["id"], result.regions["neighbor_count"]):
        assert degrees[int(rid)] == count
    assert nx.is_connected(g)
    a, b = int(result.graph.edges["a"][0]), int(result.graph.edges["b"][0])
    assert g.edges[a, b]["boundary_length_m"] == result.graph.edges["boundary_length_m"][0]
    assert g.nodes[a]["landform"] in {"cup", "trough", "rut", "saddle rut", "saddle",
                                      "saddle ridge", "ridge", "dome", "cap"}


def test_sweep(moon, cli, tmp_path):
    sweep = terrain.sweep(moon, area_ratios=[1, 0.25, 0.5])
    assert [s.ratio for s in sweep.scales] == [0.25, 0.5, 1]
    counts = [s.region_count for s in sweep.scales]
    assert counts == sorted(counts, reverse=True)
    # The finest scale is a plain segment at its ratio; the coarser ones continue from it.
    assert np.array_equal(sweep.scales[0].labels, terrain.segment(moon, area_ratio=0.25).labels)
    lineage = sweep.lineage(0)
    sums = np.bincount(lineage["from_region"], weights=lineage["fraction"])[1:]
    assert np.allclose(sums, 1.0)
    files = sweep.write(tmp_path / "py")
    assert "lineage.json" in files and "regions.gpkg" in files
    assert cli("sweep", moon, "-o", tmp_path / "cli", "--area-ratios", "0.25,0.5,1",
               "-q").returncode == 0
    for name in ("lineage.json", "labels.tif", "regions_0.5.geojson", "sweep.csv"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    with pytest.raises(terrain.Error, match="area-ratios"):
        terrain.sweep(moon, area_ratios=[0.5, 200])


def test_shape_index(result, moon):
    # The default segmentation's field is the shape index at the scale chosen per vertex.
    si = terrain.shape_index(moon, radius="auto")
    assert si.shape == result.labels.shape
    valid = np.isfinite(si)
    assert valid.mean() > 0.9
    assert si[valid].min() >= 0 and si[valid].max() <= 100
    assert np.allclose(si[valid], result.field[valid])
    rings = terrain.shape_index(moon)
    assert not np.allclose(rings[valid], si[valid])
    wider = terrain.shape_index(moon, rings=4)
    assert not np.allclose(wider[valid], rings[valid])


def test_reeb_graph(moon, cli, tmp_path):
    full = terrain.reeb_graph(moon)
    simple = terrain.reeb_graph(moon, persistence=10, area_ratio=0.5)
    assert len(simple.nodes["node"]) < len(full.nodes["node"]) == full.critical_before
    kinds = set(simple.nodes["kind"])
    assert kinds <= {"min", "max", "saddle"} and "max" in kinds
    n = len(simple.nodes["node"])
    assert simple.arcs["lower"].max() < n and simple.arcs["upper"].max() < n
    lower_values = simple.nodes["value"][simple.arcs["lower"]]
    upper_values = simple.nodes["value"][simple.arcs["upper"]]
    assert np.all(lower_values <= upper_values)
    g = simple.to_networkx()
    assert g.number_of_nodes() == n and g.number_of_edges() == len(simple.arcs["lower"])
    out = tmp_path / "reeb.json"
    assert cli("reeb", moon, "--persistence", "10", "--area-ratio", "0.5", "-o", out,
               "-q").returncode == 0
    import json

    data = json.loads(out.read_text())
    assert len(data["nodes"]) == n and len(data["arcs"]) == len(simple.arcs["lower"])
    assert sorted(node["vertex"] for node in data["nodes"]) == sorted(simple.nodes["vertex"])
    assert np.allclose(sorted(node["value"] for node in data["nodes"]),
                       np.sort(simple.nodes["value"]))
