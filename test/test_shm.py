"""A ROS process killed with SIGKILL leaves Fast DDS files in /dev/shm; the janitor
removes those, and nothing that a live process still holds."""
import os
import signal
import subprocess
import sys

from miro_ball.common.isolation import isolated_env
from miro_ball.common.shm import SharedMemoryJanitor, SHM

NODE = ('import rclpy, sys; rclpy.init(); n = rclpy.create_node("shm_probe"); '
        'p = n.create_publisher(__import__("std_msgs.msg").msg.String, "shm_probe", 1); '
        'print("up", flush=True); sys.stdin.read()')


def start():
    proc = subprocess.Popen([sys.executable, '-c', NODE], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True,
                            env=isolated_env(int(os.environ['ROS_DOMAIN_ID'])))
    assert proc.stdout.readline().strip() == 'up'
    return proc


def test_files_of_a_killed_process_are_removed_and_a_live_ones_kept():
    janitor = SharedMemoryJanitor()
    killed, alive = start(), start()
    try:
        killed.send_signal(signal.SIGKILL)
        killed.wait()
        new = set(os.listdir(SHM)) - janitor.before
        assert any(name.endswith('_el') for name in new), 'Fast DDS made no shared memory'
        assert janitor.clean() > 0
        # What is left is the live process's, and it still works: clean again finds nothing.
        left = set(os.listdir(SHM)) - janitor.before
        assert left and janitor.clean() == 0
    finally:
        alive.stdin.close()
        alive.wait(timeout=10)
