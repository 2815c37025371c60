"""One life for every node run as a program: start, spin until Ctrl+C, stop, end.

Every entry point that runs a node (the simulator, the controllers, the recorder, the GUI,
the Foxglove bridge, the clients) goes through run_node, so they all start, stop and fail
alike:

- our own SIGINT/SIGTERM handling (stopping.StopRequest): the spin ends with the context
  still up, so what the node does on its way out (a zero twist) still reaches the graph;
- a node that can not be built from what the user gave (a parameter, a name, a world) is
  said in one line on stderr, exit status 2, no traceback;
- the way out, in this order: the node's own last act while the context is up (bounded,
  and quick: fast_acks.py), the executor shut down while the node's handles are valid (else its
  ``__del__`` printed an InvalidHandle traceback at exit), the node destroyed, rclpy shut
  down; and the processes it started ended with it.

Ended by a signal, the process ends within a second. What took the time was not the
node's clean-up (10-100 ms) but a wait for an acknowledgement (the controller's zero
twist: its whole 0.5 s bound, see fast_acks.py), Python freeing every module after it
(0.2-0.9 s on a loaded machine, measured), and for the GUI its demo-mode child stopped
only after the GUI was done. So the children are told to stop first, and stop while the
node cleans up; and once everything is closed and flushed, the process ends without the
interpreter's teardown: there is nothing left for it to do but spend time.

And whatever the clean-up does, a signal is never ignored for long (_StopDeadline): a
program still there STOP_DEADLINE_S after the first SIGINT or SIGTERM, or given another
one more than REPEAT_S after it, ends at once, its children killed, exit code 128 + the
signal's number. The GUI once sat deaf through SIGINT and SIGTERM until ros2 launch killed
it (its web server could wait for ever on a page that had stopped reading: server.py).
"""
import ctypes
import faulthandler
import logging
import os
import select
import signal
import sys
import threading
import time

from miro_ball.common import proc_tree
from miro_ball.common.fast_acks import use_fast_acks

# What a node factory raises when the user's input (a parameter, a name) is wrong. rclpy's
# own classes are added where rclpy is imported (in run_node: a program's --help stays
# quick).
BAD_START = (ValueError,)
# How long the children have to stop once told (they stop as this process does, in a few
# tenths of a second); then they are killed, so that nothing outlives the program.
CHILD_GRACE_S = 0.8
KILL_WAIT_S = 0.1  # for the kernel to take a killed child away
# A spin thread (serve=) ends within a wake-up period; a callback stuck for longer than
# this is left behind with the daemon thread it runs in.
SPIN_JOIN_S = 1.0
# A stop takes well under a second (test_signals.py); ros2 launch sends SIGTERM 5 s after
# its SIGINT, and kills 5 s later. Past this, what is left of the clean-up is given up.
STOP_DEADLINE_S = 3.0
# Signals this close after the first are the same stop: a Ctrl+C in a terminal reaches a
# program and its children, and the program tells its children once more (run_node).
REPEAT_S = 1.0
SAY_S = 0.5  # for the last words of a forced end, in case stderr is a pipe nobody reads
_DISARMED = 0  # no signal's number: what close() writes to wake the watch


def first_line(err):
    """The first line of an error's message (its class name when it has none)."""
    return (str(err).strip().splitlines() or [type(err).__name__])[0]


def refuse(prog, err, code=2):
    """Say what the user gave wrong in one line on stderr and end with exit status code."""
    print(f'{prog}: error: {first_line(err)}', file=sys.stderr, flush=True)
    raise SystemExit(code)


def run_node(prog, make_node, argv=None, *, make_executor=None, on_stop=None,
             bad_start=(), fatal=(), serve=None):
    """Run the node make_node() builds until Ctrl+C, SIGTERM or its own end; the exit code.

    prog: the program's name, for its one-line errors. argv: the whole command line, its
    --ros-args included (default sys.argv; the caller has checked it with cli.user_args).
    make_executor(): what to spin on (default a SingleThreadedExecutor).
    on_stop(node): the node's last act, after the spin and before anything is shut down
    (the context is up unless something else shut it down: stop the wheels, close a file).
    It must be quick and bounded (a wait for acknowledgements takes a timeout). It may
    return an exit code for the program (a file it could not finish).
    bad_start: exception classes that mean the user's input was wrong when make_node()
    raises them (besides ValueError and rclpy's parameter and name errors): one line, exit 2.
    fatal: exception classes from a callback that end the spin: logged as one error line,
    exit code 1 (spin_until_stopped says why the others do not).
    serve(node, stop): run in the main thread while the node spins in a thread of its own
    (the GUI's web server), until stop.requested.

    A callback that raises SystemExit (a client that has done its job) ends the spin with
    its code. Ended by a signal, the process ends here once all is closed (see the module's
    docstring); otherwise the exit code is returned.
    """
    import rclpy
    from rclpy.exceptions import NameValidationException, ParameterException
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    from miro_ball.common.stopping import spin_until_stopped, StopRequest

    argv = list(sys.argv if argv is None else argv)
    # The processes this one ran before (a test that calls main()) are not the node's.
    before = set(proc_tree.descendants(os.getpid()))
    # Before rclpy.init: a signal from now on is noted, never a KeyboardInterrupt; and
    # the last message's acknowledgement comes in tens of milliseconds, not seconds.
    stop = StopRequest()
    with _StopDeadline(prog, before):
        use_fast_acks()
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
        try:
            node = make_node()
        except BAD_START + (ParameterException, NameValidationException) + tuple(bad_start) as err:
            rclpy.try_shutdown()
            refuse(prog, err)
        except BaseException:
            rclpy.try_shutdown()
            raise
        # The node's own way to end its program as Ctrl+C would, quietly (the simulator asked
        # to quit through the standard's set_simulation_state).
        node.request_stop = stop.request
        executor = (make_executor or SingleThreadedExecutor)()
        executor.add_node(node)
        code = 0
        try:
            if serve is None:
                spin_until_stopped(executor, stop, fatal=fatal)
            else:
                _serve_beside_the_spin(serve, node, executor, stop)
        except SystemExit as done:  # a client that has done its job
            code = done.code or 0
        except tuple(fatal) as err:
            node.get_logger().error(f'{err}: {prog} stopped')
            code = 1
        finally:
            # Told first, the children stop while this node cleans up, not after it: those a
            # Ctrl+C in the terminal reaches too (the simulator's eye workers, in a session of
            # their own, are stopped by its destroy_node). Whatever is left at the end is killed.
            children = [pid for pid in proc_tree.descendants(os.getpid()) if pid not in before]
            proc_tree.send(proc_tree.in_my_group(children), signal.SIGINT)
            children_by = time.monotonic() + CHILD_GRACE_S
            try:
                if on_stop is not None:
                    code = on_stop(node) or code
            finally:
                executor.shutdown()
                node.destroy_node()
                rclpy.try_shutdown()
                left = proc_tree.wait_gone(children, max(0.0, children_by - time.monotonic()))
                proc_tree.send(left, signal.SIGKILL)
                proc_tree.wait_gone(left, KILL_WAIT_S)
        if stop.signum:  # a signal, not the program's own request
            end_process(code)
        return code


def _serve_beside_the_spin(serve, node, executor, stop):
    from miro_ball.common.stopping import spin_until_stopped

    spinner = threading.Thread(target=spin_until_stopped, args=(executor, stop), daemon=True)
    spinner.start()
    try:
        serve(node, stop)
    finally:
        stop.request()  # a server that ended by itself (or failed) ends the spin too
        spinner.join(timeout=SPIN_JOIN_S)


def end_process(code):
    """End the process now with exit code ``code``, all of it closed already: what it
    printed is flushed (Python's and C's buffers), the interpreter's teardown is skipped.
    For a program stopped by a signal (run_node, the main job)."""
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe: nobody reads it any more
            pass
    ctypes.CDLL(None).fflush(None)
    os._exit(code if isinstance(code, int) else 1)  # SystemExit('why') has said why


class _StopDeadline:
    """While a node runs: STOP_DEADLINE_S after the first SIGINT or SIGTERM, or at another
    one more than REPEAT_S after it, the process ends at once (_end), whatever its main
    thread is doing.

    Python runs a signal's handler in the main thread, and only between bytecodes: a main
    thread blocked in a C call, or waiting on a page for ever, never gets to it. But the
    C-level handler writes every signal's number to the wakeup fd at once, so a thread of
    our own reads the signals from there, and keeps the time.
    """

    def __init__(self, prog, before):
        self.prog, self.before = prog, before
        self._read, self._write = os.pipe()
        os.set_blocking(self._write, False)  # as set_wakeup_fd wants it
        self._previous = signal.set_wakeup_fd(self._write, warn_on_full_buffer=False)
        self._watch = threading.Thread(target=self._watching, name='stop deadline',
                                       daemon=True)
        self._watch.start()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        """The node has ended and run_node returns (a program that calls it and goes on,
        a test): the wakeup fd is given back, the watch ends."""
        signal.set_wakeup_fd(self._previous)
        os.write(self._write, bytes([_DISARMED]))
        self._watch.join()
        os.close(self._read)
        os.close(self._write)

    def _watching(self):
        first, since = None, None  # the first stop signal's number, and when it came
        while True:
            wait = None if since is None else max(0.0, since + STOP_DEADLINE_S - time.monotonic())
            if not select.select([self._read], [], [], wait)[0]:
                self._end(first, f'still running {STOP_DEADLINE_S:g} s after '
                                 f'{signal.Signals(first).name}', stacks=True)
            for signum in os.read(self._read, 64):
                if signum == _DISARMED:
                    return
                if signum not in (signal.SIGINT, signal.SIGTERM):
                    continue
                if since is None:
                    first, since = signum, time.monotonic()
                elif time.monotonic() - since > REPEAT_S:
                    self._end(signum, f'{signal.Signals(signum).name} while it was stopping')

    def _end(self, signum, why, stacks=False):
        """End now: the children killed, a line on stderr (and what each thread was doing,
        for a report, when the deadline passed), exit code 128 + signum. Nothing that the
        stuck main thread may hold is touched (logging's or stderr's locks)."""
        children = [pid for pid in proc_tree.descendants(os.getpid()) if pid not in self.before]
        proc_tree.send(children, signal.SIGKILL)
        line = (f'{self.prog}: {why}: ended without finishing its clean-up '
                f'(exit code {128 + signum})\n')

        def say():
            os.write(2, line.encode())
            if stacks:
                faulthandler.dump_traceback(file=2, all_threads=True)
        saying = threading.Thread(target=say, daemon=True)
        saying.start()
        saying.join(SAY_S)
        os._exit(128 + signum)
