"""How the algorithms reach terrain: its Python module when it can be imported, else the
`terrain` command line. Where to look is, in order: the environment (TERRAIN_PYTHONPATH,
TERRAIN_CLI; TERRAIN_BACKEND=cli forces the command line), local.json beside this file
(written by `./setup.sh qgis`), then Python's path and PATH."""

import json
import os
import re
import shutil
import subprocess
import sys

from qgis.core import QgsProcessingException

_HERE = os.path.dirname(os.path.abspath(__file__))


def _local():
    try:
        with open(os.path.join(_HERE, "local.json"), encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def module():
    """terrain's Python module, or None (then the command line is used)."""
    if os.environ.get("TERRAIN_BACKEND") == "cli":
        return None
    for path in (os.environ.get("TERRAIN_PYTHONPATH"), _local().get("pythonpath")):
        if path and os.path.isdir(path) and path not in sys.path:
            sys.path.insert(0, path)
    try:
        import terrain

        return terrain
    except ImportError:
        return None


def cli():
    """The terrain program, or None."""
    for path in (os.environ.get("TERRAIN_CLI"), _local().get("cli")):
        if path and os.access(path, os.X_OK):
            return path
    return shutil.which("terrain")


def describe():
    if module() is not None:
        return "Python module"
    return "command line" if cli() else "not found: run ./setup.sh qgis"


def progress_callback(feedback, start, end):
    """A terrain progress callable that drives QGIS's progress bar over [start, end] percent
    and cancels when the user cancels."""

    def progress(fraction, message):
        feedback.setProgress(start + (end - start) * fraction)
        return not feedback.isCanceled()

    return progress


def library_error(error):
    return QgsProcessingException(str(error))


def run_cli(args, feedback):
    """Runs `terrain ARGS`, turning its progress bar ("0...10...20") into QGIS progress and
    its one-line errors into QgsProcessingException. Returns its standard output."""
    program = cli()
    if program is None:
        raise QgsProcessingException(
            "terrain was not found: neither its Python module nor the terrain program; "
            "run ./setup.sh qgis in the terrain repository (docs/qgis.md)")
    feedback.pushCommandInfo(" ".join([program, *args]))
    err = []
    with subprocess.Popen([program, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True) as process:
        token = ""
        while True:
            ch = process.stderr.read(1)
            if not ch:
                break
            err.append(ch)
            if ch.isdigit():
                token += ch
            else:
                if token and ch == ".":
                    feedback.setProgress(float(token))
                token = ""
            if feedback.isCanceled():
                process.terminate()
                break
        out = process.stdout.read()
        status = process.wait()
    if feedback.isCanceled():
        raise QgsProcessingException("cancelled")
    if status != 0:
        lines = [line for line in "".join(err).splitlines() if line.strip()]
        message = lines[-1] if lines else f"terrain exited with status {status}"
        message = re.sub(r"^[0-9.]*(\s*-\s*done\.)?\s*", "", message)
        raise QgsProcessingException(message)
    for line in out.splitlines():
        feedback.pushInfo(line)
    return out


def cli_options(options):
    """Keyword options as command-line options: area_ratio=0.5 -> --area-ratio 0.5."""
    args = []
    for name, value in options.items():
        flag = "--" + name.replace("_", "-")
        if isinstance(value, bool):
            if value:
                args.append(flag)
        else:
            args += [flag, str(value)]
    return args
