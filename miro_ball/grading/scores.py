"""What an episode of grading scored, and how a grade is shown: plain Python, no ROS.

The grader (grader.py) fills in the facts of each episode; this module says
what they mean (success, what went wrong with the command) and writes the
table, the total and the JSON.
"""
import json
import math
import statistics
from dataclasses import asdict, dataclass, field

# MiRo's platform takes one command per 20 ms tick (50 per s); ten times that is a flood.
FLOOD_PER_SIM_S = 500.0
TAIL_LINES = 5
TAIL_WIDTH = 160


@dataclass
class EpisodeResult:
    index: int  # 1-based
    robot: tuple  # placement: x, y (m), yaw (rad)
    ball: tuple  # placement: x, y (m)
    kicked: bool = False
    time_to_kick: float | None = None  # simulated s from the start of the episode
    fell: bool = False
    distance_m: float = 0.0  # driven over the floor
    sim_time: float = 0.0  # simulated s the episode lasted
    wall_time: float = 0.0  # s, from starting the processes to stopping them
    ended: str = ''  # why the episode stopped: kicked, fell, limit, command exited, ...
    commands: int = 0  # messages the command published on control/cmd_vel
    exit_code: int | None = None  # when the command ended by itself
    exited_after_s: float | None = None  # wall s after its start
    killed: bool = False  # it ignored Ctrl+C for the grace period
    output_tail: list = field(default_factory=list)  # its last lines when something was wrong

    @property
    def success(self):
        return self.kicked and not self.fell

    @property
    def notes(self):
        """What went wrong with the command, in words."""
        notes = []
        if self.exit_code is not None:
            notes.append(f'exited with code {self.exit_code} after {self.exited_after_s:.1f} s')
        if self.commands == 0:
            notes.append('never published on control/cmd_vel')
        elif self.sim_time > 0 and self.commands / self.sim_time > FLOOD_PER_SIM_S:
            notes.append(f'flooded control/cmd_vel: {self.commands / self.sim_time:.0f} '
                         f'messages per simulated second')
        if self.killed:
            notes.append('ignored Ctrl+C, killed')
        if self.ended not in ('', 'kicked', 'fell', 'limit', 'command exited'):
            notes.append(self.ended)
        return notes

    def as_json(self):
        data = asdict(self)
        data.update(robot=list(self.robot), ball=list(self.ball), success=self.success,
                    notes=self.notes)
        return data


def printable_tail(raw, lines=TAIL_LINES, width=TAIL_WIDTH):
    """The last non-empty lines of a program's output (bytes), safe to print: undecodable
    bytes and control characters become '?', long lines are cut."""
    text = raw.decode('utf-8', errors='replace')
    cleaned = [''.join(c if c.isprintable() and c != '\ufffd' else '?' for c in line).strip()
               for line in text.replace('\r', '\n').split('\n')]
    return [line[:width] + ('...' if len(line) > width else '')
            for line in cleaned if line][-lines:]


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
            f'{"; ".join(r.notes)}').rstrip()


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
            lines += ['', f'episode {r.index}: {"; ".join(r.notes) or r.ended}; the last lines '
                          f'of its output:'] + [f'    {line}' for line in r.output_tail]
    return '\n'.join(lines)


def to_json(results):
    return json.dumps([r.as_json() for r in sorted(results, key=lambda r: r.index)], indent=2)
