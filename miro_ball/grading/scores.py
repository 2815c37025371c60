"""How one command's grade is shown in the terminal: plain Python, no ROS.

The episodes are the report's dicts (episode_facts.complete): a table, the total, then
the last output lines of every command that went wrong. A class's report is
class_report.py.
"""
import math
import statistics


def _seconds(value):
    return '-' if value is None else f'{value:.1f} s'


def placement_text(robot, ball):
    x, y, yaw = robot
    return f'robot ({x:5.2f}, {y:5.2f}, {math.degrees(yaw):4.0f} deg), ball ' \
           f'({ball[0]:5.2f}, {ball[1]:5.2f})'


def episode_line(r):
    """One row of the table."""
    return (f'{r["index"]:>3}  {placement_text(r["robot"], r["ball"])}  '
            f'{"yes" if r["kicked"] else "no":<6} {_seconds(r["time_to_kick"]):>8}  '
            f'{"FELL" if r["fell"] else "no":<4} {r["distance_m"]:5.2f} m  '
            f'{"; ".join(r["notes"])}').rstrip()


PLACEMENT_WIDTH = len(placement_text((0.0, 0.0, 0.0), (0.0, 0.0)))
HEADER = f'{"#":>3}  {"placement":<{PLACEMENT_WIDTH}}  kicked  to kick  fell   driven  notes'


def total_line(results, planned):
    """The grade: episodes won (kicked without falling or cheating), out of those planned."""
    wins = sum(r['success'] for r in results)
    times = [r['time_to_kick'] for r in results if r['success']]
    median = f', median time to kick {statistics.median(times):.1f} s' if times else ''
    partial = f' (only {len(results)} ran)' if len(results) < planned else ''
    cheated = sum(bool(r['cheated']) for r in results)
    return (f'score {wins}/{planned} ({100 * wins / planned:.0f} %){partial}: kicked '
            f'{sum(r["kicked"] for r in results)}{median}, fell '
            f'{sum(r["fell"] for r in results)}, cheated {cheated}, driven '
            f'{sum(r["distance_m"] for r in results):.2f} m in all')


def report(results, planned):
    """Table, total, then the last output lines of every command that went wrong."""
    ordered = sorted(results, key=lambda r: r['index'])
    lines = [HEADER] + [episode_line(r) for r in ordered] + ['', total_line(ordered, planned)]
    for r in ordered:
        if r['output_tail'] and not r['success']:
            lines += ['', f'episode {r["index"]}: {"; ".join(r["notes"]) or r["ended"]}; the '
                          f'last lines of its output:'] + [f'    {line}'
                                                           for line in r['output_tail']]
    return '\n'.join(lines)
