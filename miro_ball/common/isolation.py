"""A ROS domain of its own for a run, so tests, benchmarks and the demo never see
other ROS processes on the machine (or each other when they run side by side)."""
import os

DISCOVERY = {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'}


def private_domain(salt=0):
    """A ROS domain id in 1..100 spread by process id; salt separates users in one process."""
    return 1 + (os.getpid() + salt) % 100


def private_domains(count, salt=0):
    """count distinct ROS domain ids, one per worker of a run (count <= 100)."""
    base = private_domain(salt)
    return [1 + (base + k) % 100 for k in range(count)]


def limit_discovery():
    """Keep this process's discovery on this host (unless the user chose otherwise)."""
    for name, value in DISCOVERY.items():
        os.environ.setdefault(name, value)


def isolated_env(domain_id):
    """Environment for child processes: the given domain, this host only, unbuffered."""
    return dict(os.environ, ROS_DOMAIN_ID=str(domain_id), PYTHONUNBUFFERED='1', **DISCOVERY)
