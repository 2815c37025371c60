"""A network namespace of its own for each grading host: only a loopback, so a graded
command that changes ROS_DOMAIN_ID, or looks for other episodes, finds nobody.

As root, ``unshare --net``; otherwise a user namespace too (``unshare --user
--map-root-user --net``), where the kernel allows it. Where neither works, the host runs
in the machine's network on a ROS domain of its own (common/isolation.py), as the grader
did before, and the report says so.
"""
import fcntl
import os
import shutil
import socket
import struct
import subprocess
from functools import lru_cache

SIOCGIFFLAGS, SIOCSIFFLAGS = 0x8913, 0x8914
IFF_UP = 0x1
IFREQ = '16sH22x'  # struct ifreq: the name, then the flags, padded to 40 bytes


def _prefix():
    prefix = [shutil.which('unshare') or 'unshare']
    if os.geteuid() != 0:
        prefix += ['--user', '--map-root-user']
    return prefix + ['--net', '--']


@lru_cache(maxsize=1)
def namespace_prefix():
    """(argv prefix that starts a program in a new network namespace, or [], and a
    sentence for the report saying how episodes are kept apart)."""
    prefix = _prefix()
    try:
        done = subprocess.run(prefix + ['true'], capture_output=True, timeout=10)
        why = done.stderr.decode(errors='replace').strip().splitlines()[-1:] \
            if done.returncode else None
    except (OSError, subprocess.TimeoutExpired) as err:
        why = [str(err)]
    if why is None:
        return prefix, ('each episode ran in a network namespace of its own (only a '
                        'loopback): no episode could reach another')
    return [], (f'no network namespace here ({"; ".join(why) or "unshare failed"}): episodes '
                f'were kept apart by ROS domains only, which a command can change')


def loopback_up():
    """Bring up the namespace's loopback, which starts down (as `ip link set lo up`)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        flags = struct.unpack(IFREQ, fcntl.ioctl(sock, SIOCGIFFLAGS,
                                                 struct.pack(IFREQ, b'lo', 0)))[1]
        fcntl.ioctl(sock, SIOCSIFFLAGS, struct.pack(IFREQ, b'lo', flags | IFF_UP))
