"""Runs one of the lab's scripts as a user would, for the lab's tests."""
import os
import stat
import subprocess
import sys

LAB = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(script, *args):
    """Standard output of `python3 scripts/lab/SCRIPT ARGS...`; raises, with its output, unless
    it succeeds."""
    out = subprocess.run([sys.executable, os.path.join(LAB, script), *map(str, args)],
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise AssertionError(f"{script} {' '.join(map(str, args))} failed ({out.returncode}):\n"
                             f"{out.stdout}\n{out.stderr}")
    return out.stdout


def write_executable(path, text):
    """Writes `text` to `path` as an executable: a stand-in binary for a lab test."""
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, os.stat(path).st_mode | stat.S_IEXEC)
    return path
