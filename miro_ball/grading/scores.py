"""How a grade is shown: plain Python, no ROS.

The episodes (miro_ball.run.episode) give the facts of each; this module says
what went wrong with the command and writes the table, the total and the JSON.
"""
import json
import math
import statistics
from dataclasses import asdict

# MiRo's platform takes one command per 20 ms tick (50 per s); ten times that is a flood.
FLOOD_PER_SIM_S = 500.0


def notes(r):
    """What went wrong with the command of EpisodeResult r, in words."""
    said = []
    if r.exit_code is not None:
        said.append(f'exited with code {r.exit_code} after {r.exited_after_s:.1f} s')
    if r.commands == 0:
        said.append('never published on control/cmd_vel')
    elif r.sim_time > 0 and r.commands / r.sim_time > FLOOD_PER_SIM_S:
        said.append(f'flooded control/cmd_vel: {r.commands / r.sim_time:.0f} '
                    f'messages per simulated second')
    if r.killed:
        said.append('ignored Ctrl+C, killed')
    if r.ended not in ('', 'kicked', 'fell', 'limit', 'command exited'):
        said.append(r.ended)
    return said


def _seconds(value):
    return '-' if value is None else f'{value:.1f} s'


def placement_text(robot, ball):
    x, y, yaw = robot
    return f'robot ({x:5.2f}, {y:5.2f}, {math.degrees(yaw):4.0f} deg), ball ' \
           f'({ball[0]:5.2f}, {ball[1]:5.2f})'


def episode_line(r):
    """One row of the table."""
    return (f'{r.index:>3}  {placement_text(r.robot, r.ball)}  '
            f'{"yes" if r.kicked else "no":<6} {_seconds(r.time_to_kick):>8}  '
            f'{"FELL" if r.fell else "no":<4} {r.distance_m:5.2f} m  '
            f'{"; ".join(notes(r))}').rstrip()


PLACEMENT_WIDTH = len(placement_text((0.0, 0.0, 0.0), (0.0, 0.0)))
HEADER = f'{"#":>3}  {"placement":<{PLACEMENT_WIDTH}}  kicked  to kick  fell   driven  notes'


def total_line(results, planned):
    """The grade: episodes kicked without falling, out of those planned."""
    wins = sum(r.success for r in results)
    times = [r.time_to_kick for r in results if r.success]
    median = f', median time to kick {statistics.median(times):.1f} s' if times else ''
    partial = f' (only {len(results)} ran)' if len(results) < planned else ''
    return (f'score {wins}/{planned} ({100 * wins / planned:.0f} %){partial}: kicked '
            f'{sum(r.kicked for r in results)}{median}, fell {sum(r.fell for r in results)}, '
            f'driven {sum(r.distance_m for r in results):.2f} m in all')


def report(results, planned):
    """Table, total, then the last output lines of every command that went wrong."""
    ordered = sorted(results, key=lambda r: r.index)
    lines = [HEADER] + [episode_line(r) for r in ordered] + ['', total_line(ordered, planned)]
    for r in ordered:
        if r.output_tail:
            lines += ['', f'episode {r.index}: {"; ".join(notes(r)) or r.ended}; the last '
                          f'lines of its output:'] + [f'    {line}' for line in r.output_tail]
    return '\n'.join(lines)


def as_json(r):
    data = asdict(r)
    data.update(robot=list(r.robot), ball=list(r.ball), success=r.success, notes=notes(r))
    return data


def to_json(results):
    return json.dumps([as_json(r) for r in sorted(results, key=lambda r: r.index)], indent=2)
