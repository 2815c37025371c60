"""A ROS domain of its own for a run, so tests, benchmarks and the lab run never see
other ROS processes on the machine (or each other when they run side by side).

A domain id chosen from the process id alone collides now and then (1 in 100 per
pair of runs), and two runs on one domain see each other's /clock and topics. So
each domain is claimed with a lock file that the claiming process holds until it
exits: two processes of ours on one machine never get the same domain.
"""
import fcntl
import os
import tempfile
from pathlib import Path

DISCOVERY = {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'}
DOMAINS = range(1, 101)  # ROS_DOMAIN_ID 0 is everybody's default: left alone
LOCK_DIR = Path(tempfile.gettempdir()) / 'miro_ball_domains'
_claimed = {}  # domain id -> its open lock file, held for the life of this process


def _claim(domain):
    try:
        LOCK_DIR.mkdir(exist_ok=True)
        lock = open(LOCK_DIR / f'{domain}.lock', 'w')
    except OSError:
        return False
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:  # another process holds it
        lock.close()
        return False
    _claimed[domain] = lock
    return True


def private_domains(count, salt=0):
    """count ROS domain ids that no other process of ours holds, claimed for the life of
    this process; the search starts at a place spread by process id and salt."""
    start = (os.getpid() + salt) % len(DOMAINS)
    found = []
    for k in range(len(DOMAINS)):
        domain = DOMAINS[(start + k) % len(DOMAINS)]
        if domain not in _claimed and _claim(domain):
            found.append(domain)
            if len(found) == count:
                return found
    raise RuntimeError(f'no free ROS domain on this machine ({len(_claimed)} held by this '
                       f'process; see {LOCK_DIR})')


def private_domain(salt=0):
    """One ROS domain id of its own for this run (see private_domains)."""
    return private_domains(1, salt)[0]


def limit_discovery():
    """Keep this process's discovery on this host (unless the user chose otherwise)."""
    for name, value in DISCOVERY.items():
        os.environ.setdefault(name, value)


def isolated_env(domain_id):
    """Environment for child processes: the given domain, this host only, unbuffered."""
    return dict(os.environ, ROS_DOMAIN_ID=str(domain_id), PYTHONUNBUFFERED='1', **DISCOVERY)
