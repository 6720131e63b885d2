"""The outputs read back through the GIS clients Debian ships (networkx, GDAL, geopandas,
rasterio), exactly as docs/outputs.md tells a user to."""

import json
import re

import pytest

from conftest import SOURCE_DIR

OUTPUTS_MD = SOURCE_DIR / "docs" / "outputs.md"


def doc_snippet(marker):
    """The ```python block of docs/outputs.md that contains `marker`."""
    blocks = re.findall(r"```python\n(.*?)```", OUTPUTS_MD.read_text(), re.S)
    found = [b for b in blocks if marker in b]
    assert len(found) == 1, f"docs/outputs.md has no single python block with {marker!r}"
    # The blocks are indented inside list items.
    lines = found[0].splitlines()
    indent = min(len(l) - len(l.lstrip()) for l in lines if l.strip())
    return "\n".join(l[indent:] for l in lines)


@pytest.fixture(scope="module")
def moon_out(cli, moon, tmp_path_factory):
    out = tmp_path_factory.mktemp("gis") / "out"
    done = cli("segment", moon, "-o", out, "-q")
    assert done.returncode == 0, done.stderr
    return out


def test_networkx_loads_adjacency_json_as_documented(moon_out, monkeypatch):
    nx = pytest.importorskip("networkx")
    code = doc_snippet("adjacency.json")
    monkeypatch.chdir(moon_out.parent)
    scope = {}
    exec(compile(code, str(OUTPUTS_MD), "exec"), scope)
    graph = scope["graph"]
    assert isinstance(graph, nx.Graph) and not graph.is_directed()
    data = json.loads((moon_out / "adjacency.json").read_text())
    assert graph.number_of_nodes() == len(data["nodes"]) > 1
    assert graph.number_of_edges() == len(data["edges"]) > 0
    edge = data["edges"][0]
    assert graph.has_edge(edge["source"], edge["target"])
    assert graph.nodes[1]["landform"] == data["nodes"][0]["landform"]

