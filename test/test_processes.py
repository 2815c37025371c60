"""The process supervisor of every run: Ctrl+C as a terminal sends it, a kill for those that
ignore it, and nothing a child started outlives the run."""
import sys
import time

from miro_ball.run.processes import Processes

PY = sys.executable
HANG_GUARD_S = 30.0
# Says it is ready, then waits for Ctrl+C and says it got it.
POLITE = ('import signal, sys, time\n'
          'def stop(*_):\n'
          '    print("stopped by Ctrl+C", flush=True); sys.exit(0)\n'
          'signal.signal(signal.SIGINT, stop)\n'
          'print("ready", flush=True)\n'
          'time.sleep(1000)\n')


def wait_for_line(log, line):
    """Until the child wrote line into its log (a hang guard only)."""
    deadline = time.monotonic() + HANG_GUARD_S
    while line not in log.read_text():
        assert time.monotonic() < deadline, log.read_text()
        time.sleep(0.05)


def running(pid):
    """Whether pid is a live process (a zombie is not)."""
    try:
        with open(f'/proc/{pid}/stat') as stat:
            return stat.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except FileNotFoundError:
        return False


def test_a_child_stops_on_ctrl_c_and_says_so_in_its_log(tmp_path):
    with Processes(tmp_path) as procs:
        procs.start('polite', [PY, '-c', POLITE])
        wait_for_line(tmp_path / 'polite.log', 'ready')
        assert procs.stop(grace_s=HANG_GUARD_S) == []
    assert (tmp_path / 'polite.log').read_text().splitlines() == ['ready', 'stopped by Ctrl+C']


def test_ctrl_c_reaches_the_program_a_shell_script_runs(tmp_path):
    """A shell passes no signal on to the program it waits for; a terminal's Ctrl+C goes to
    the whole process group, and so does ours."""
    script = f'{PY} -c \'{POLITE}\'; echo after'
    with Processes(tmp_path) as procs:
        procs.start('script', ['sh', '-c', script])
        wait_for_line(tmp_path / 'script.log', 'ready')
        assert procs.stop(grace_s=HANG_GUARD_S) == []
    assert 'stopped by Ctrl+C' in (tmp_path / 'script.log').read_text()


def test_one_that_ignores_ctrl_c_is_killed_with_everything_it_started(tmp_path):
    stubborn = 'trap "" INT; sleep 1000 & echo $!; wait'
    with Processes(tmp_path) as procs:
        procs.start('stubborn', ['sh', '-c', stubborn])
        log = tmp_path / 'stubborn.log'
        deadline = time.monotonic() + HANG_GUARD_S
        while not log.read_text().strip():
            assert time.monotonic() < deadline
            time.sleep(0.05)
        helper = int(log.read_text().split()[0])
        assert running(helper)
        assert procs.stop(grace_s=0.5) == ['stubborn']
    assert not running(helper)


def test_a_child_that_ended_by_itself_is_named_with_its_exit_code(tmp_path):
    with Processes(tmp_path) as procs:
        procs.start('sleeper', [PY, '-c', 'import time; time.sleep(1000)'])
        quitter = procs.start('quitter', [PY, '-c', 'raise SystemExit(3)'])
        quitter.wait(timeout=HANG_GUARD_S)
        assert procs.dead() == ('quitter', 3)
        assert list(procs.pids()) == ['sleeper']
