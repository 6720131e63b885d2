#!/usr/bin/python3
"""Runs docs/tutorial.ipynb with nbclient, as ctest's python_tutorial does; fails when a cell
fails. The committed notebook must hold no outputs; each cell tagged "figure:NAME" must draw
a PNG. With --figures DIR, writes those PNGs as DIR/NAME.png (docs/images: the figures of
docs/python.md).

    PYTHONPATH=build/python /usr/bin/python3 tests/python/run_tutorial.py [--figures docs/images]
"""

import argparse
import base64
import os
import pathlib
import sys
import tempfile
import time

import nbclient
import nbformat

NOTEBOOK = pathlib.Path(__file__).resolve().parents[2] / "docs" / "tutorial.ipynb"


def figure_name(cell):
    tags = [t for t in cell.metadata.get("tags", []) if t.startswith("figure:")]
    return tags[0].split(":", 1)[1] if tags else None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", type=pathlib.Path, help="write the tagged figures here")
    args = parser.parse_args()

    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(nb)
    for i, cell in enumerate(nb.cells):
        if cell.cell_type == "code" and (cell.outputs or cell.execution_count is not None):
            sys.exit(f"{NOTEBOOK}: cell {i} holds outputs; commit the notebook cleared")
    # The kernel python3 is /usr/bin/python3 (Debian's ipykernel); it inherits PYTHONPATH,
    # made absolute since it runs in docs/.
    paths = os.environ.get("PYTHONPATH", "").split(os.pathsep)
    os.environ["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in paths if p)
    os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")  # ipykernel's debugger notes
    start = time.perf_counter()
    client = nbclient.NotebookClient(nb, kernel_name="python3", timeout=300,
                                     resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    with tempfile.TemporaryDirectory(prefix="terrain-tutorial-") as tmp:
        os.environ["TMPDIR"] = tmp  # where the notebook writes its rasters
        client.execute()  # raises CellExecutionError, with the cell and its traceback
    print(f"{NOTEBOOK.name}: {len(nb.cells)} cells run in {time.perf_counter() - start:.1f} s")

    for i, cell in enumerate(nb.cells):
        name = figure_name(cell)
        if name is None:
            continue
        pngs = [o["data"]["image/png"] for o in cell.outputs if "image/png" in o.get("data", {})]
        if len(pngs) != 1:
            sys.exit(f"cell {i} (figure {name}) drew {len(pngs)} PNG(s), not one")
        if args.figures:
            path = args.figures / f"{name}.png"
            path.write_bytes(base64.b64decode(pngs[0]))
            print(f"wrote {path} ({path.stat().st_size} bytes)")


if __name__ == "__main__":
    main()
