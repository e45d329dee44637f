"""Long work runs off the GIL and stops on Ctrl-C: a long simulation in a child process gets
SIGINT and raises KeyboardInterrupt within a second or two, after which the module runs again;
while a simulation runs, other Python threads keep running; a progress callback that raises
stops the work with its exception."""

import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest

import stirling

CHILD = textwrap.dedent(
    """
    import signal, sys, time
    import stirling

    # Ctrl-C raises KeyboardInterrupt, as in an interactive session; a child started from a
    # shell that ignores SIGINT (a background job, `nohup`) inherits the ignore and Python
    # keeps it, so the signal would never arrive
    signal.signal(signal.SIGINT, signal.default_int_handler)

    m = stirling.load("nsection", n=40)
    started = []

    def progress(done, total, line):
        if not started:
            started.append(time.monotonic())
            print("started", flush=True)

    try:
        m.simulate(10000.0, samples=2, progress=progress)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted after %.3f s" % (time.monotonic() - started[0]), flush=True)
    s = m.simulate(0.01, samples=11)
    print("after %.2f" % s.t[-1], flush=True)
    """
)


def test_ctrl_c_stops_a_long_simulation():
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = child.stdout.readline()
        assert line.strip() == "started", line + child.stderr.read()
        time.sleep(0.5)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=60)
        stopped = time.monotonic() - sent
    finally:
        child.kill()
    assert "interrupted after" in out, out + err
    assert "after 0.01" in out, out + err
    assert child.returncode == 0, err
    assert stopped < 5.0, f"took {stopped:.2f} s to stop"


def test_other_threads_run_while_a_simulation_runs():
    m = stirling.load("nsection", n=40)
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.001)

    th = threading.Thread(target=count)
    th.start()
    t0 = time.monotonic()
    before = len(ticks)
    # long enough to see the counter move (0.2 s of a release build, more in debug); the
    # bar is on the counter's rate, not on the run's length, which depends on the build
    m.simulate(30.0, samples=2)
    took = time.monotonic() - t0
    during = len(ticks) - before
    stop.set()
    th.join()
    # with the GIL held the counter could not move during the run: it ticks about once a
    # millisecond when free; ask for a fifth of that
    assert took > 0.05, f"the run took {took:.3f} s: too short to tell"
    assert during > 0.2 * took / 0.001, (took, during)


def test_progress_reaches_the_end_and_an_exception_in_it_stops_the_work():
    m = stirling.load("cv1")
    seen = []
    m.simulate(0.5, progress=lambda done, total, line: seen.append((done, total)))
    assert seen and seen[-1][1] == 0.5 and abs(seen[-1][0] - 0.5) < 1e-3
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))

    class Stop(Exception):
        pass

    def boom(done, total, line):
        raise Stop("from the callback")

    with pytest.raises(Stop, match="from the callback"):
        stirling.load("nsection", n=20).simulate(50.0, samples=2, progress=boom)
    # the stop request is withdrawn: the next run completes
    assert m.simulate(0.05).t[-1] == 0.05


def test_progress_bar_with_tqdm(capsys):
    stirling.load("cv1").simulate(0.2, progress=True)
    err = capsys.readouterr().err
    assert "simulating" in err
