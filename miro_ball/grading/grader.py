"""Grading any controller: episodes from seeded placements, each with a fresh simulator and
the command under test as processes of their own on a ROS domain of their own
(miro_ball.run.process_rig), several at a time.
"""
import queue
from concurrent.futures import ThreadPoolExecutor

from miro_ball.common.isolation import private_domains
from miro_ball.grading.scores import placement_text
from miro_ball.run.episode import run_episode
from miro_ball.run.process_rig import ProcessRig


def grade(placements, options, jobs, stop, log=print):
    """EpisodeResults of the episodes run (all unless stop was requested), ``jobs`` at a
    time, each on a ROS domain of its own. options: a process_rig.Options."""
    domains = queue.Queue()
    for domain in private_domains(jobs, salt=75):
        domains.put(domain)

    def progress(index):
        return lambda referee: log(f'  episode {index}: t = {referee.elapsed:5.1f} s '
                                   f'simulated, ball moved {referee.monitor.moved:4.2f} m')

    def work(index, placement):
        if stop.requested:
            return None
        domain = domains.get()
        try:
            log(f'  episode {index}/{len(placements)}: '
                f'{placement_text(placement.robot, placement.ball)}')
            return run_episode(ProcessRig(options, index, domain, stop), placement, index,
                               options.limit_s, progress=progress(index))
        finally:
            domains.put(domain)

    results = []
    with ThreadPoolExecutor(jobs) as pool:
        futures = [pool.submit(work, index, placement)
                   for index, placement in enumerate(placements, 1)]
        for future in futures:
            result = future.result()
            if result is not None:
                results.append(result)
                mark = 'kicked in %.1f s' % result.time_to_kick if result.kicked else 'no kick'
                log(f'  episode {result.index}: {mark}, {result.ended} '
                    f'({result.wall_time:.0f} s wall)')
    return results
