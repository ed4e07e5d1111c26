"""Two .ci/sanitize runs at once share build/sanitize; the second waits for the first, and says
so, instead of breaking its build."""

import fcntl
import os
import select
import shutil
import signal
import subprocess

import pytest

from conftest import NO_SOURCE, SOURCE

SCRIPT = SOURCE / ".ci" / "sanitize"


@pytest.mark.skipif(not SCRIPT.is_file(), reason=NO_SOURCE)
@pytest.mark.skipif(shutil.which("flock") is None, reason="no flock here (util-linux)")
def test_a_second_sanitize_run_waits_for_the_first():
    folder = SOURCE / "build" / "sanitize"
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / ".lock", "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            pytest.skip("a .ci/sanitize run is going on now")
        run = subprocess.Popen(
            [str(SCRIPT), "python", "-c", "pass"], stderr=subprocess.PIPE, text=True, start_new_session=True
        )
        try:
            ready, _, _ = select.select([run.stderr], [], [], 60)
            assert ready, "no word from the second run in 60 s"
            said = run.stderr.readline()  # printed before it waits; then it blocks on the lock
            assert "another run holds" in said and "waiting for it" in said
            assert run.poll() is None  # still waiting: nothing built while the first runs
        finally:
            os.killpg(run.pid, signal.SIGKILL)
            run.wait()
