"""Huge pages (docs/performance.md): a Python process started with glibc's tunable pages its
large arrays with them, and the results do not change."""

import os
import subprocess
import sys

import numpy as np

import terrain
from conftest import SAMPLE_FILES

try:
    with open("/sys/kernel/mm/transparent_hugepage/enabled") as f:
        MODE = f.read().split("[")[1].split("]")[0]  # "always [madvise] never"
except (OSError, IndexError):
    MODE = ""  # no transparent huge pages

# Labels of the Vesta sample, written as .npy by a child Python process.
CHILD = """
import sys, numpy, terrain
numpy.save(sys.argv[2], terrain.segment(sys.argv[1]).labels)
print(terrain.page_use())
"""


def run_child(tmp_path, name, tunables):
    env = dict(os.environ)
    env.pop("GLIBC_TUNABLES", None)
    if tunables:
        env["GLIBC_TUNABLES"] = tunables
    out = tmp_path / (name + ".npy")
    done = subprocess.run([sys.executable, "-c", CHILD, str(SAMPLE_FILES["vesta"]), str(out)],
                          env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip(), np.load(out)


def test_a_process_started_with_the_tunable_uses_huge_pages_with_the_same_labels(tmp_path):
    asked, with_huge = run_child(tmp_path, "huge", "glibc.malloc.hugetlb=1")
    plain, without = run_child(tmp_path, "normal", "")
    assert asked == ("huge" if MODE in ("always", "madvise") else "normal")
    assert plain == ("huge" if MODE == "always" else "normal")
    assert np.array_equal(with_huge, without)
    assert with_huge.min() >= 1
    assert terrain.page_use() in ("huge", "normal")
