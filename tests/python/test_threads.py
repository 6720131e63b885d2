"""Python threads: four segmentations at once give the bytes of four one after the other; a
callback that cancels, or raises, stops its own call and leaves the others intact."""

import threading
import time

import numpy as np
import pytest

import terrain
from conftest import SAMPLE_FILES

# Four DEMs, each with the options it runs with: three with the landform defaults, the
# 512 x 512 Vesta tile at the paper's single scale (the defaults take several seconds there).
JOBS = {
    "moon4c": (SAMPLE_FILES["moon4c"], {}),
    "moon1g": (SAMPLE_FILES["moon1g"], {}),
    "marsc": (SAMPLE_FILES["marsc"], {}),
    "vesta": (SAMPLE_FILES["vesta"], {"persistence": 10, "area_ratio": 0.5}),
}


def run(job, progress=None):
    path, options = job
    return terrain.segment(str(path), progress=progress, **options)


def outputs(result):
    """Every per-pixel and per-region array of a result, as bytes."""
    out = {"labels": result.labels.tobytes(), "field": result.field.tobytes()}
    for key, column in result.regions.items():
        out["regions." + key] = np.asarray(column).tobytes()
    for key, column in result.graph.edges.items():
        out["edges." + key] = np.asarray(column).tobytes()
    return out


@pytest.fixture(scope="module")
def one_after_the_other():
    return {name: outputs(run(job)) for name, job in JOBS.items()}


def at_once(callbacks, jobs=JOBS):
    """Runs the jobs in threads released together; returns {name: result or the exception
    raised} and {name: (start, end)} of each call, time.perf_counter()."""
    barrier = threading.Barrier(len(jobs))
    results, spans = {}, {}

    def work(name):
        barrier.wait()
        start = time.perf_counter()
        try:
            results[name] = run(jobs[name], callbacks.get(name))
        except BaseException as e:  # noqa: B902 - handed to the test
            results[name] = e
        spans[name] = (start, time.perf_counter())

    threads = [threading.Thread(target=work, args=(name,)) for name in jobs]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return results, spans


def assert_intact(results, reference, names):
    for name in names:
        assert isinstance(results[name], terrain.SegmentResult), (name, results[name])
        got = outputs(results[name])
        assert got.keys() == reference[name].keys()
        for key in got:
            assert got[key] == reference[name][key], (name, key)


def test_four_threads_give_the_bytes_of_one_after_the_other(one_after_the_other):
    calls = {name: 0 for name in JOBS}

    def counter(name):
        def progress(fraction, message):
            calls[name] += 1
            return True

        return progress

    results, spans = at_once({name: counter(name) for name in JOBS})
    assert_intact(results, one_after_the_other, JOBS)
    # The four calls ran at the same time: one moment lies inside all four.
    assert max(s for s, _ in spans.values()) < min(e for _, e in spans.values())
    assert all(n > 0 for n in calls.values())


def test_a_cancelling_callback_stops_its_own_call_only(one_after_the_other):
    seen = []

    def cancel(fraction, message):
        seen.append(fraction)
        return fraction < 0.3

    results, _ = at_once({"moon1g": cancel})
    assert isinstance(results["moon1g"], terrain.Error)
    assert "cancelled" in str(results["moon1g"])
    # Cancelled at the first step past 0.3: the call did not go on to the end.
    assert seen[-1] >= 0.3 and max(seen) < 1.0
    assert_intact(results, one_after_the_other, [n for n in JOBS if n != "moon1g"])


def test_an_exception_in_one_thread_leaves_the_others_intact(one_after_the_other):
    class Stop(Exception):
        pass

    def fail(fraction, message):
        if fraction > 0.3:
            raise Stop("raised by the vesta job's callback")
        return True

    results, _ = at_once({"vesta": fail})
    assert isinstance(results["vesta"], Stop)
    assert str(results["vesta"]) == "raised by the vesta job's callback"
    assert_intact(results, one_after_the_other, [n for n in JOBS if n != "vesta"])

def test_the_library_s_error_in_one_thread_leaves_the_others_intact(one_after_the_other):
    # The read of a missing file fails inside the library, without the GIL, as the others
    # run.
    jobs = dict(JOBS, marsc=("/no/such/dem.tif", {}))
    results, _ = at_once({}, jobs)
    assert isinstance(results["marsc"], terrain.Error)
    assert str(results["marsc"]).startswith("read: '/no/such/dem.tif' does not exist")
    assert_intact(results, one_after_the_other, [n for n in JOBS if n != "marsc"])
