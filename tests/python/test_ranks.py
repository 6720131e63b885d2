"""`mpirun -np N terrain segment`, `sweep` and `field` (docs/scale.md, "Ranks"): the ranks make
the field's bands of rows together and rank 0 writes; the outputs are those of one process, byte for byte, at 1, 2
and 4 ranks; an error on any rank stops every rank with one line naming it."""

import os
import shutil
import subprocess

import pytest

from conftest import SAMPLE_FILES

MPIRUN = shutil.which("mpirun")
# As root (CI machines), with more ranks than cores; -q keeps Open MPI's own banners out, so
# that an error is terrain's one line.
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def mpirun(ranks, *args, env=None):
    assert MPIRUN, "mpirun not found: ./setup.sh installs openmpi-bin"
    command = [MPIRUN, "-q", "--oversubscribe", "-np", str(ranks)]
    for name in (env or {}):
        command += ["-x", name]
    return subprocess.run(command + [os.environ["TERRAIN_CLI"], *map(str, args)],
                          capture_output=True, text=True, timeout=120,
                          env=dict(ENV, **(env or {})))


def files(directory):
    """Every output file's bytes (in subdirectories too) but run.json's (its timings and
    versions), by path within the directory."""
    return {str(p.relative_to(directory)): p.read_bytes() for p in sorted(directory.rglob("*"))
            if p.is_file() and p.name != "run.json"}


@pytest.mark.parametrize("sample", ["vesta", "moon1g"])
def test_ranks_write_the_outputs_of_one_process(cli, tmp_path, sample):
    # The Vesta tile and the global 1-degree Moon (poles, seam), with the defaults (the
    # ladder's field, which splits).
    dem = SAMPLE_FILES[sample]
    one = cli("segment", "-q", dem, "-o", tmp_path / "one")
    assert one.returncode == 0, one.stderr
    expected = files(tmp_path / "one")
    assert "labels.tif" in expected and "regions.geojson" in expected
    for ranks in (1, 2, 4):
        out = tmp_path / f"ranks{ranks}"
        run = mpirun(ranks, "segment", "-q", dem, "-o", out)
        assert run.returncode == 0, run.stderr
        assert run.stderr == ""
        # One summary line: rank 0 alone reports.
        assert run.stdout.count("regions on") == 1, run.stdout
        assert files(out) == expected, f"{ranks} ranks"


def test_ranks_sweep_as_one_process(cli, tmp_path):
    # terrain sweep splits its field the same way (the ladder's, with --radius auto).
    dem = SAMPLE_FILES["vesta"]
    args = ["--radius", "auto", "--area-ratios", "0.1,0.5,2"]
    one = cli("sweep", "-q", dem, "-o", tmp_path / "one", *args)
    assert one.returncode == 0, one.stderr
    run = mpirun(3, "sweep", "-q", dem, "-o", tmp_path / "three", *args)
    assert run.returncode == 0, run.stderr
    assert run.stdout.count("scales;") == 1, run.stdout
    expected = files(tmp_path / "one")
    assert len(expected) > 10 and files(tmp_path / "three") == expected


def test_ranks_make_terrain_fields_raster_as_one_process(cli, tmp_path):
    # terrain field --radius auto: the field and the radius each pixel took, both rasters.
    dem = SAMPLE_FILES["moon1g"]
    one = cli("field", "-q", dem, "--radius", "auto", "-o", tmp_path / "one.tif")
    assert one.returncode == 0, one.stderr
    run = mpirun(2, "field", "-q", dem, "--radius", "auto", "-o", tmp_path / "two.tif")
    assert run.returncode == 0, run.stderr
    assert run.stdout.count("shape_index on") == 1, run.stdout
    for one_file, two_file in (("one.tif", "two.tif"), ("one_radius.tif", "two_radius.tif")):
        assert (tmp_path / two_file).read_bytes() == (tmp_path / one_file).read_bytes()


def test_a_field_that_does_not_split_is_made_on_rank_zero(cli, tmp_path):
    # The paper's single scale (--rings): rank 0 does the whole run, the others wait.
    dem = SAMPLE_FILES["vesta"]
    args = ["--area-ratio", "0.5", "--persistence", "10"]
    assert cli("segment", "-q", dem, "-o", tmp_path / "one", *args).returncode == 0
    run = mpirun(2, "segment", "-q", dem, "-o", tmp_path / "two", *args)
    assert run.returncode == 0, run.stderr
    assert files(tmp_path / "two") == files(tmp_path / "one")


def test_an_error_on_one_rank_stops_every_rank_with_one_line(tmp_path):
    # Rank 1 fails in the field's gathering (TERRAIN_FAIL_RANK, for the tests): rank 0,
    # waiting for its part, stops too; nothing is written.
    run = mpirun(2, "segment", "-q", SAMPLE_FILES["vesta"], "-o", tmp_path / "out",
                 env={"TERRAIN_FAIL_RANK": "1"})
    assert run.returncode == 1
    assert run.stderr.strip().splitlines() == [
        "terrain segment: rank 1: segment: stopped on purpose by TERRAIN_FAIL_RANK"]
    assert not (tmp_path / "out").exists()


def test_a_bad_output_is_reported_once_by_rank_zero(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "labels.tif").write_bytes(b"an earlier run's")
    run = mpirun(4, "segment", "-q", SAMPLE_FILES["vesta"], "-o", tmp_path / "out")
    assert run.returncode == 1
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("terrain segment: rank 0: "), run.stderr
    assert "--overwrite" in lines[0]
