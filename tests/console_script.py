"""The console script run as a user runs it, timed by the CPU seconds the process spent.

Tests that bound how fast a refusal comes bound its CPU time, not its wall time: the suite runs on
several workers of a shared machine, which stretch the wall clock of every process but not its CPU
time. A process still running after ``hang`` wall seconds is killed, and the test fails.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
import threading
from collections.abc import Sequence
from dataclasses import dataclass

import pytest


@dataclass(frozen=True)
class ConsoleRun:
    result: subprocess.CompletedProcess[str]
    cpu_seconds: float  # user and system time of the process and the children it waited for


def run_console(arguments: Sequence[str], hang: float) -> ConsoleRun:
    """Run ``arguments`` to the end, its output captured; fail the test if it runs ``hang`` seconds."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        process = subprocess.Popen(list(arguments), stdout=out, stderr=err)
        killed = threading.Event()
        timer = threading.Timer(hang, lambda: (killed.set(), process.kill()))
        timer.start()
        _, status, usage = os.wait4(process.pid, 0)  # reaps the process with its own resource usage
        process.returncode = os.waitstatus_to_exitcode(status)  # set before the timer stops: no kill after reaping
        timer.cancel()
        if killed.is_set():
            pytest.fail(f"{' '.join(arguments)[:120]} still ran after {hang} s")
        out.seek(0)
        err.seek(0)
        result = subprocess.CompletedProcess(list(arguments), process.returncode, out.read().decode(), err.read().decode())
    return ConsoleRun(result, usage.ru_utime + usage.ru_stime)
