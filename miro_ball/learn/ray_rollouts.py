"""Episodes on a Ray cluster (pip install -e '.[scale]'): training past one machine.

``RayRollouts(address)`` is a pool as rollouts.evaluate_population takes one: its
``imap(function, jobs)`` runs each job as a Ray task of one CPU, anywhere in the cluster, and
gives the results back in the jobs' order. A node runs as many episodes at a time as it has
CPUs. Ray keeps a worker process from one task to the next, and each process keeps its
environment (rollouts builds it on the process's first episode): an episode on Ray costs a
reset, as in a local pool, not a world build. Ray runs a task again elsewhere when its node
is lost (max_retries). Every node needs this package installed, as the grader's do.
"""
from miro_ball.grading.ray_pool import RETRIES, connect


def _in_worker(function, job):
    import cv2

    cv2.setNumThreads(1)  # a task has one CPU: OpenCV's own threads would only contend
    return function(job)


class RayRollouts:
    """A pool of the Ray cluster at ``address`` ('auto': the one this machine is in);
    RayUnavailable (one line) if Ray is not installed or nothing answers there."""

    def __init__(self, address):
        self.ray = connect(address)
        self.remote = self.ray.remote(num_cpus=1, max_retries=RETRIES)(_in_worker)
        self.pending = {}  # task -> the index of its job

    def imap(self, function, jobs, chunksize=1):
        """function(job) of each job, in order, as each is ready (chunksize: as a
        multiprocessing Pool's, not used: a task is one episode). Two tasks a CPU of the
        cluster are out at a time, the next sent as one ends. Two nodes of one CPU here, the
        trainer's episodes: all sent at once, the head node's queue kept most of them and the
        other node ran dry (1.57x one node's speed); one a CPU, the other node's worker waited
        about 70 ms for each next task (1.65x); two a CPU, 1.80x."""
        ray, jobs = self.ray, list(jobs)
        width = 2 * max(1, int(ray.cluster_resources().get('CPU', 1)))
        ready, sent, given = {}, 0, 0
        while given < len(jobs):
            while sent < len(jobs) and len(self.pending) < width:
                self.pending[self.remote.remote(function, jobs[sent])] = sent
                sent += 1
            if given in ready:
                yield ready.pop(given)
                given += 1
                continue
            [task], _ = ray.wait(list(self.pending), num_returns=1)
            ready[self.pending.pop(task)] = ray.get(task)

    def terminate(self):
        """Cancel what is still to run and leave the cluster (it keeps running)."""
        for task in self.pending:
            self.ray.cancel(task, force=True)
        self.pending = {}
        self.ray.shutdown()


def ray_pool(address, refuse):
    """RayRollouts(address), or ``refuse(one line)`` (a parser's error) if Ray is not
    installed or no cluster answers there."""
    from miro_ball.grading.ray_pool import RayUnavailable

    try:
        return RayRollouts(address)
    except RayUnavailable as err:
        refuse(str(err))
