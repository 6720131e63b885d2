"""Runs a command while sampling one of its figures, and splits the samples by the stage times
`terrain segment` writes in run.json: shared by stage_memory.py and bench_global.py."""
import os
import subprocess
import time


def run_sampled(command, sample, period, **popen):
    """Runs `command` (a list; keyword arguments go to subprocess.Popen), calling sample(pid)
    every `period` seconds while it runs; returns (exit code, wall seconds, resource usage of the
    finished process as os.wait4 gives it, samples as (seconds since the start, value)) for the
    samples that were not None."""
    start = time.monotonic()
    process = subprocess.Popen(command, **popen)
    samples = []
    while True:
        pid, status, usage = os.wait4(process.pid, os.WNOHANG)
        if pid:
            break
        value = sample(process.pid)
        if value is not None:
            samples.append((time.monotonic() - start, value))
        time.sleep(period)
    process.returncode = os.waitstatus_to_exitcode(status)
    return process, time.monotonic() - start, usage, samples


def stage_spans(timings, begin):
    """(stage, start, end) in turn for run.json's timings_seconds (but its total), the first
    stage starting at `begin` seconds."""
    for name, seconds in timings.items():
        if name == "total":
            continue
        yield name, begin, begin + seconds
        begin += seconds
