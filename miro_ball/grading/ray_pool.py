"""Episodes as tasks on a Ray cluster (pip install -e '.[scale]'): grading past one machine.

Each task runs one episode on a grading host of its Ray worker process, kept from one
task to the next as a local worker keeps its host, and returns the result with the
episode's files (its log and video) as bytes: the nodes need not share a disk. Ray
runs a task again elsewhere when its node is lost (max_retries); each episode's result
is taken once, from the task that finished, so none is lost or counted twice. A task
uses one CPU of its node: a node runs as many episodes at a time as it has CPUs.
"""
import socket
import tempfile
from dataclasses import asdict
from pathlib import Path

from miro_ball.grading.hosts import HostSettings, run_on

RETRIES = 3  # per task, when its node or worker process is lost
WAIT_S = 1.0  # between looks for finished tasks (and at a Ctrl+C)
CONNECT_S = 5.0  # for the cluster's address to answer at all
_hosts = {}  # in a Ray worker process: HostSettings -> its grading host


class RayUnavailable(RuntimeError):
    """Ray is not installed, or no cluster answers; the message says which, in one line."""


def episode_task(settings, spec):
    """In a Ray worker: (result, {file name: bytes}, node id) of one episode."""
    import ray

    settings = HostSettings(**settings)
    scratch = Path(tempfile.gettempdir()) / 'miro_ball_ray'
    scratch.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory(dir=scratch) as out:
        result, _hosts[settings] = run_on(_hosts.get(settings), dict(spec, out=out), settings,
                                          scratch / 'host.log')
        files = {path.name: path.read_bytes() for path in Path(out).iterdir()
                 if path.is_file()}
    return result, files, ray.get_runtime_context().get_node_id()


def _answers(address, timeout_s=CONNECT_S):
    """Whether anything listens at a Ray address ([ray://]host:port): ray.init would retry
    an address where nothing does for minutes."""
    host, _, port = address.split('://', 1)[-1].rpartition(':')
    try:
        socket.create_connection((host or 'localhost', int(port)), timeout=timeout_s).close()
    except (OSError, ValueError):
        return False
    return True


def connect(address):
    """The ray module, joined to the cluster at ``address`` ('auto': the one this machine
    is in); RayUnavailable if Ray is not installed or nothing answers there."""
    try:
        import ray
    except ImportError:
        raise RayUnavailable("--ray needs Ray: pip install -e '.[scale]'") from None
    if address != 'auto' and not _answers(address):
        raise RayUnavailable(f'--ray: no Ray cluster answers at {address} (start one with '
                             '`ray start --head`, or check the address and port)')
    try:
        ray.init(address=address, logging_level='ERROR', log_to_driver=False)
    except (ConnectionError, RuntimeError, ValueError) as err:
        raise RayUnavailable(f'--ray: no Ray cluster at {address}: '
                             f'{str(err).splitlines()[0]}') from None
    return ray


class RayPool:
    """run(specs, done) as LocalPool does, on the Ray cluster at ``address`` ('auto': the
    one this machine is in)."""

    def __init__(self, settings, address, stop=None):
        ray = connect(address)
        self.ray, self.settings, self.stop = ray, settings, stop
        self.remote = ray.remote(num_cpus=1, max_retries=RETRIES)(episode_task)

    def run(self, specs, done, log_dir=None):
        """As LocalPool.run; the hosts' logs stay on their nodes (log_dir is not used)."""
        ray = self.ray
        pending = {self.remote.remote(asdict(self.settings), spec): spec for spec in specs}
        try:
            while pending and not (self.stop and self.stop.requested):
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=WAIT_S)
                for ref in ready:
                    spec = pending.pop(ref)
                    result, files, node = ray.get(ref)
                    out = Path(spec['out'])
                    out.mkdir(parents=True, exist_ok=True)
                    for name, data in files.items():
                        (out / name).write_bytes(data)
                    done(spec, dict(result, ran_on=node))
        finally:
            for ref in pending:
                ray.cancel(ref, force=True)
            ray.shutdown()
