"""An episode of a grading, before and after: the request a host runs (``spec``) and the
result the report shows (``complete``), both plain dicts that travel as JSON (to a host's
stdin, to a Ray task and back). Plain Python.
"""
from pathlib import PurePosixPath

COMMAND_FOLDER = 'command'  # the episodes' folder of a single command (no student)


def episode_folder(student, index):
    """Where an episode's files go, relative to the report folder."""
    return str(PurePosixPath(student or COMMAND_FOLDER) / f'episode_{index:02d}')


def spec(student, index, placement, command, workdir, out, *, limit_s, grace_s,
         command_wait_s, video, hidden=()):
    """What a host needs to run one episode (host.py's request). out: the folder for its
    files (command.log, video.mp4)."""
    return {'student': student, 'index': index, 'robot': list(placement.robot),
            'ball': list(placement.ball), 'command': list(command), 'workdir': str(workdir),
            'out': str(out), 'limit_s': limit_s, 'grace_s': grace_s,
            'command_wait_s': command_wait_s, 'video': video,
            'hidden': [str(h) for h in hidden]}


def complete(spec, result):
    """The report's episode: the host's result with who, where, and what it comes to."""
    episode = dict(result, student=spec['student'], index=spec['index'],
                   robot=spec['robot'], ball=spec['ball'])
    early = episode['ended'] == 'command exited'
    episode['crashed'] = early and episode['exit_code'] not in (0, None)
    episode['success'] = bool(episode['kicked'] and not episode['fell']
                              and not episode['cheated'])
    if episode.get('video'):
        episode['video'] = str(PurePosixPath(episode_folder(spec['student'], spec['index']))
                               / episode['video'])
    episode['notes'] = notes(episode)
    if episode['success']:
        episode['output_tail'] = []  # shown only when something went wrong
    return episode


# MiRo's platform takes one command per 20 ms tick (50 per s); ten times that is a flood.
FLOOD_PER_SIM_S = 500.0


def notes(r):
    """What went wrong with the command of episode r, in words."""
    said = []
    if r.get('cheated'):
        said.append(f'cheated: {r["cheated"]}')
    if r['exit_code'] is not None:
        said.append(f'exited with code {r["exit_code"]} after {r["sim_time"]:.1f} s '
                    f'simulated')
    if r['commands'] == 0:
        said.append('never published on control/cmd_vel')
    elif r['sim_time'] > 0 and r['commands'] / r['sim_time'] > FLOOD_PER_SIM_S:
        said.append(f'flooded control/cmd_vel: {r["commands"] / r["sim_time"]:.0f} '
                    f'messages per simulated second')
    if r['killed']:
        said.append('ignored Ctrl+C, killed')
    if r['ended'] not in ('', 'kicked', 'fell', 'limit', 'command exited', 'cheated'):
        said.append(r['ended'])
    return said
